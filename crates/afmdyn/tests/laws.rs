//! Tip–sample laws on the hybrid-system core: a conformance suite for every law × integrator
//! pair; the linear law through the adaptive integrator against the exact propagator; Hertz and
//! DMT orbits and multipliers against an independent integrator written here (its own force
//! formulas, fixed-step RK4 with bisection events, finite-difference monodromy); variational
//! Jacobians against finite differences; the impact law against the closed-form N = 1 flight,
//! its energy loss, the grazing singularity and chattering; every analysis on every law.

use afmdyn::analysis::continuation::{continue_branch, BranchEnd, ContinuationSpec};
use afmdyn::analysis::lyapunov::{lyapunov_spectrum, LyapunovOptions};
use afmdyn::analysis::progress::Progress;
use afmdyn::analysis::shooting::{floquet_multipliers, shoot, ShootingOptions};
use afmdyn::analysis::steady::{steady_state, Motion, SteadyOptions};
use afmdyn::galerkin::Region;
use afmdyn::integrate::{advance_dyn, build, IntegratorKind, IntegratorOptions, SwitchEvent};
use afmdyn::maps::flow::flow;
use afmdyn::maps::StroboscopicMap;
use afmdyn::request::analyses::OrbitRequest;
use afmdyn::{CantileverModel, ContactLaw, EventKind, Params, SweepParam};
use nalgebra::{Complex, DMatrix, DVector};
use proptest::prelude::*;

use super::common;
use common::laws::{CAP, DMT, ES, JKR, SLS};
use common::{events_until, impact_model, opts};

// One conformance suite over every law × integrator pair: tests/conformance.rs.

/// The split integrator (exact free flight, adaptive contact) against the adaptive integrator
/// alone at a tight tolerance (1e-14), from rest over 30 drive periods of time (N = 3). Linear and
/// Hertz laws: the same events (kind, regions) at the same times to 1e-8 and the same final state
/// to 1e-8. Impact law (r = 0.6, 0.9, and r = 0: plastic impacts and sticking): its transients
/// amplify differences (chattering sequences, the square-root singularity of low-velocity
/// impacts), so after some tens of events any two integrators part; the split integrator keeps
/// to the tight oracle (events matched in kind and to 1e-8 in time) at least as long as the
/// adaptive integrator at the default tolerance 1e-12 does, and for at least 8 events. Then the
/// period-1 orbits' Floquet multipliers (variational equations in contact, e^{A_I t} over the
/// free stints, saltation at the events) agree to 1e-7.
#[test]
fn split_integrator_agrees_with_the_adaptive_oracle() {
    let events = |m: &CantileverModel, kind, tol, t_end| {
        let mut it = build(m, opts(kind, tol), 0.0, &m.rest()).unwrap();
        let ev = events_until(it.as_mut(), t_end);
        (ev, it.state().clone())
    };
    let matched = |a: &[SwitchEvent], b: &[SwitchEvent]| {
        a.iter()
            .zip(b)
            .take_while(|(x, y)| {
                (x.kind, x.from, x.to) == (y.kind, y.from, y.to) && (x.tau - y.tau).abs() < 1e-8
            })
            .count()
    };
    for law in [
        ContactLaw::Linear,
        ContactLaw::Hertz,
        ContactLaw::Impact { restitution: 0.6 },
        ContactLaw::Impact { restitution: 0.9 },
        ContactLaw::Impact { restitution: 0.0 },
    ] {
        let (p, m) = law_model(law, 3, 2.6);
        let t_end = 30.0 * p.period();
        let (e1, z1) = events(&m, IntegratorKind::Split, 1e-12, t_end);
        let (e2, z2) = events(&m, IntegratorKind::Adaptive, 1e-14, t_end);
        assert!(e1.len() >= 20, "{law}: {} events", e1.len());
        if law.restitution().is_none() {
            assert_eq!((e1.len(), matched(&e1, &e2)), (e2.len(), e2.len()), "{law}");
            let d = (z1 - z2).amax();
            assert!(d < 1e-8, "{law}: final state differs by {d:e}");
        } else {
            let (e3, _) = events(&m, IntegratorKind::Adaptive, 1e-12, t_end);
            let (split, default) = (matched(&e1, &e2), matched(&e3, &e2));
            assert!(
                split >= default.max(8),
                "{law}: {split} vs {default} events"
            );
        }
    }
    // a stable Hertz orbit and an unstable impacting one (a Neimark–Sacker pair outside the
    // unit circle), each shot from the steady state reached from rest, as `afmdyn orbit` does
    for m in [
        law_model(ContactLaw::Hertz, 3, 2.8).1,
        impact_model(0.6, 3, 0.05, 2.8),
    ] {
        let law = *m.law();
        let (guess, _) = OrbitRequest::default().start.guess(&m).unwrap();
        let orbit = |kind| {
            let o = opts(
                kind,
                if kind == IntegratorKind::Split {
                    1e-12
                } else {
                    1e-14
                },
            );
            let mut it = build(&m, o, 0.0, &m.rest()).unwrap();
            let map = &mut StroboscopicMap::new(it.as_mut(), 1);
            shoot(map, &guess, &ShootingOptions::default()).unwrap()
        };
        let (a, b) = (
            orbit(IntegratorKind::Split),
            orbit(IntegratorKind::Adaptive),
        );
        assert!((&a.state - &b.state).amax() < 1e-8, "{law}: orbit");
        assert!(a.switchings >= 1, "{law}: the orbit touches the sample");
        for (x, y) in a.multipliers.iter().zip(&b.multipliers) {
            assert!((x - y).norm() < 1e-7, "{law}: multiplier {x} vs {y}");
        }
    }
}

#[test]
fn unsupported_pairs_are_typed_errors() {
    let hertz = CantileverModel::new(&Params {
        contact_law: ContactLaw::Hertz,
        ..Params::default()
    })
    .unwrap();
    let e = build(
        &hertz,
        opts(IntegratorKind::Exact, 1e-12),
        0.0,
        &hertz.rest(),
    );
    assert!(common::is_refusal(&e, "exact", Some("hertz")));
    let impact = CantileverModel::new(&Params {
        contact_law: ContactLaw::Impact { restitution: 0.5 },
        ..Params::default()
    })
    .unwrap();
    let e = build(
        &impact,
        opts(IntegratorKind::Rk4, 1e-12),
        0.0,
        &impact.rest(),
    );
    assert!(common::is_refusal(&e, "rk4", None));
    assert_eq!(IntegratorKind::Auto.resolve(&hertz), IntegratorKind::Split);
    assert_eq!(IntegratorKind::Auto.resolve(&impact), IntegratorKind::Split);
    let plastic = impact_model(0.0, 3, 0.0, 2.6);
    assert_eq!(
        IntegratorKind::Auto.resolve(&plastic),
        IntegratorKind::Adaptive
    );
    let (_, dmt) = law_model(DMT, 3, 2.6);
    assert_eq!(IntegratorKind::Auto.resolve(&dmt), IntegratorKind::Taylor);
    let e = build(&dmt, opts(IntegratorKind::Split, 1e-12), 0.0, &dmt.rest());
    assert!(common::is_refusal(&e, "split", Some("dmt")));
    for (bad, field) in [
        (ContactLaw::Impact { restitution: 1.5 }, "restitution"),
        (
            ContactLaw::Dmt {
                hamaker: -1.0,
                intermolecular_distance: 0.01,
            },
            "hamaker",
        ),
        (
            ContactLaw::Dmt {
                hamaker: 1.0,
                intermolecular_distance: 0.0,
            },
            "intermolecular_distance",
        ),
    ] {
        let err = CantileverModel::new(&Params {
            contact_law: bad,
            ..Params::default()
        })
        .unwrap_err();
        assert!(err.to_string().contains(field), "{err}");
    }
}

// ------------------------------------------------- linear law: adaptive against exact

#[test]
fn linear_law_adaptive_reproduces_exact() {
    let p = Params {
        omega: 2.8,
        ..Params::default()
    };
    let m = CantileverModel::new(&p).unwrap();
    let mut ex = build(&m, opts(IntegratorKind::Exact, 1e-12), 0.0, &m.rest()).unwrap();
    let mut ad = build(&m, opts(IntegratorKind::Adaptive, 1e-13), 0.0, &m.rest()).unwrap();
    let t = 20.0 * m.period();
    let (e1, e2) = (events_until(ex.as_mut(), t), events_until(ad.as_mut(), t));
    assert_eq!(e1.len(), e2.len());
    for (a, b) in e1.iter().zip(&e2) {
        assert!((a.tau - b.tau).abs() < 1e-9, "{} vs {}", a.tau, b.tau);
    }
    let err = (ex.state() - ad.state()).amax();
    assert!(err < 1e-9, "state {err:e}");
    // the period-2 orbit and its Floquet multipliers, monodromy by variational equations +
    // saltation against exact transition matrices + saltation
    let mut ss = build(&m, opts(IntegratorKind::Exact, 1e-12), 0.0, &m.rest()).unwrap();
    let guess = steady_state(ss.as_mut(), &SteadyOptions::default())
        .unwrap()
        .end_state()
        .clone();
    let two = ShootingOptions::default().with_period(2);
    let o_ex = shoot(&mut StroboscopicMap::new(ex.as_mut(), 1), &guess, &two).unwrap();
    let o_ad = shoot(&mut StroboscopicMap::new(ad.as_mut(), 1), &guess, &two).unwrap();
    assert!((&o_ex.state - &o_ad.state).amax() < 1e-9);
    for (a, b) in o_ex.multipliers.iter().zip(&o_ad.multipliers) {
        assert!((a - b).norm() < 1e-7, "{a} vs {b}");
    }
}

// ---------------------------------------- an independent integrator for Hertz and DMT

/// The model written again from the Galerkin matrices (eqs. 11–14, `common::FreeBeam`) with its
/// own force laws: M ä + C ȧ + K a = F(τ) + φ F_c, F_c from the formulas of Johnson (Hertz) and
/// DMT.
struct Independent {
    beam: common::FreeBeam,
    p: Params,
}

impl Independent {
    fn new(p: &Params) -> Self {
        Independent {
            beam: common::FreeBeam::of(&CantileverModel::new(p).unwrap()),
            p: *p,
        }
    }
    fn v_t(&self, tau: f64, z: &DVector<f64>) -> (f64, f64) {
        self.beam.v_t(tau, z)
    }
    fn force(&self, contact: bool, tau: f64, z: &DVector<f64>) -> f64 {
        let (v, vd) = self.v_t(tau, z);
        let (d, dd) = (-v, -vd);
        let (k, c) = (self.p.alpha4, self.p.alpha6);
        match self.p.contact_law {
            ContactLaw::Hertz if contact => k * d.max(0.0).powf(1.5) + c * dd,
            ContactLaw::Dmt {
                hamaker: h,
                intermolecular_distance: a0,
            } => {
                if contact {
                    -h / (a0 * a0) + k * d.max(0.0).powf(1.5) + c * d.max(0.0).sqrt() * dd
                } else {
                    -h / ((a0 + v) * (a0 + v))
                }
            }
            // Hudlet et al. 1998: the biased sphere over the plane, −ẼR̃²/(d(d + R̃)), added to
            // DMT's van der Waals force and saturated at d = a₀ in contact
            ContactLaw::Electrostatic {
                hamaker: h,
                intermolecular_distance: a0,
                electrostatic: e,
                tip_radius: r,
            } => {
                let attraction = |dist: f64| -h / (dist * dist) - e * r * r / (dist * (dist + r));
                if contact {
                    attraction(a0) + k * d.max(0.0).powf(1.5) + c * d.max(0.0).sqrt() * dd
                } else {
                    attraction(a0 + v)
                }
            }
            _ => 0.0,
        }
    }
    fn rhs(&self, contact: bool, tau: f64, z: &DVector<f64>) -> DVector<f64> {
        let f = self.force(contact, tau, z);
        self.beam.rhs(tau, z, f, 2 * self.p.modes)
    }
    /// z(t1) from z(0) = z0 with `m` RK4 steps per period; a sign change of V_T inside a step is
    /// located by bisection on the step length and the region switched there
    /// (`common::rk4_switched_flow`).
    fn flow(&self, z0: &DVector<f64>, t1: f64, m: usize) -> DVector<f64> {
        common::rk4_switched_flow(
            &|contact, tau, z| self.rhs(contact, tau, z),
            &|tau, z| self.v_t(tau, z).0 < 0.0,
            z0,
            t1,
            self.p.period() / m as f64,
        )
    }
    /// Newton shooting of a period-n orbit with a central-difference monodromy; returns the
    /// orbit's state and its Floquet multipliers.
    fn orbit(&self, guess: &DVector<f64>, n: usize, m: usize) -> (DVector<f64>, Vec<Complex<f64>>) {
        let t = n as f64 * self.p.period();
        let dim = guess.len();
        let mut z = guess.clone();
        let mono = |z: &DVector<f64>| {
            let eps = 1e-6;
            let mut j = DMatrix::zeros(dim, dim);
            for k in 0..dim {
                let mut zp = z.clone();
                let mut zm = z.clone();
                zp[k] += eps;
                zm[k] -= eps;
                j.set_column(
                    k,
                    &((self.flow(&zp, t, m) - self.flow(&zm, t, m)) / (2.0 * eps)),
                );
            }
            j
        };
        for _ in 0..8 {
            let f = self.flow(&z, t, m) - &z;
            if f.norm() < 1e-13 {
                break;
            }
            let a = mono(&z) - DMatrix::identity(dim, dim);
            z -= a.lu().solve(&f).unwrap();
        }
        (z.clone(), floquet_multipliers(&mono(&z)))
    }
}

fn law_model(law: ContactLaw, modes: usize, omega: f64) -> (Params, CantileverModel) {
    let p = Params {
        modes,
        omega,
        contact_law: law,
        ..Params::default()
    };
    (p, CantileverModel::new(&p).unwrap())
}

/// Hertz, DMT and electrostatic period-1 orbits at Ω = 2.8 (N = 2): state and Floquet
/// multipliers from the
/// adaptive integrator (variational equations + saltation) against the independent integrator
/// (RK4, 40 000 steps per period, finite-difference monodromy) to 1e-7. DMT is compared without
/// its Kelvin–Voigt term: α6 √δ δ̇ has an unbounded derivative at contact onset, where fixed-step
/// RK4 loses its order (its error there is ≈ 1e-6); the Kelvin–Voigt monodromy is checked against
/// finite differences of the map in `dmt_kelvin_voigt_monodromy_matches_finite_differences`.
#[test]
fn hertz_and_dmt_orbits_agree_with_an_independent_integrator() {
    for (law, alpha6) in [(ContactLaw::Hertz, 0.2), (DMT, 0.0), (ES, 0.0)] {
        let p = Params {
            modes: 2,
            omega: 2.8,
            alpha6,
            contact_law: law,
            ..Params::default()
        };
        let m = CantileverModel::new(&p).unwrap();
        let mut it = build(&m, IntegratorOptions::default(), 0.0, &m.rest()).unwrap();
        let map = &mut StroboscopicMap::new(it.as_mut(), 1);
        let o = shoot(map, &m.rest(), &ShootingOptions::default()).unwrap();
        let ind = Independent::new(&p);
        let (z, mu) = ind.orbit(&o.state, 1, 40_000);
        let err = (&z - &o.state).amax();
        assert!(err < 1e-7, "{law}: orbit differs by {err:e}");
        for (a, b) in o.multipliers.iter().zip(&mu) {
            assert!((a - b).norm() < 1e-7, "{law}: multiplier {a} vs {b}");
        }
        assert!(o.switchings >= 2, "{law}: the orbit touches the sample");
    }
}

/// DMT with Kelvin–Voigt damping: the monodromy from the variational equations in tangent
/// coordinates equals central differences of the stroboscopic map (ε = 1e-6: truncation ε² and
/// the integration error 1e-14/ε), and the orbit agrees with the independent RK4 to its accuracy.
#[test]
fn dmt_kelvin_voigt_monodromy_matches_finite_differences() {
    let (p, m) = law_model(DMT, 2, 2.8);
    let tight = IntegratorOptions {
        tolerance: 1e-14,
        ..Default::default()
    };
    let mut it = build(&m, tight, 0.0, &m.rest()).unwrap();
    let map = &mut StroboscopicMap::new(it.as_mut(), 1);
    let o = shoot(map, &m.rest(), &ShootingOptions::default()).unwrap();
    let dim = o.state.len();
    let eps = 1e-6;
    let mut fd = DMatrix::zeros(dim, dim);
    for k in 0..dim {
        let (mut zp, mut zm) = (o.state.clone(), o.state.clone());
        zp[k] += eps;
        zm[k] -= eps;
        let a = StroboscopicMap::new(it.as_mut(), 1)
            .apply(&zp)
            .unwrap()
            .state;
        let b = StroboscopicMap::new(it.as_mut(), 1)
            .apply(&zm)
            .unwrap()
            .state;
        fd.set_column(k, &((a - b) / (2.0 * eps)));
    }
    let err = (&fd - &o.monodromy).amax();
    assert!(err < 1e-7, "monodromy vs finite differences: {err:e}");
    let (z, _) = Independent::new(&p).orbit(&o.state, 1, 40_000);
    assert!((&z - &o.state).amax() < 1e-5);
}

// ----------------------------------------------- variational equations: finite differences

fn fd_flow_jacobian(m: &CantileverModel, z0: &DVector<f64>, t1: f64, eps: f64) -> DMatrix<f64> {
    let mut it = build(m, opts(IntegratorKind::Adaptive, 1e-13), 0.0, z0).unwrap();
    let mut flow = |z: &DVector<f64>| {
        it.reset(0.0, z).unwrap();
        advance_dyn(it.as_mut(), t1, &mut |_, _, _| Ok(())).unwrap();
        it.state().clone()
    };
    let dim = z0.len();
    let mut j = DMatrix::zeros(dim, dim);
    for k in 0..dim {
        let (mut zp, mut zm) = (z0.clone(), z0.clone());
        zp[k] += eps;
        zm[k] -= eps;
        j.set_column(k, &((flow(&zp) - flow(&zm)) / (2.0 * eps)));
    }
    j
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 6,
        failure_persistence: super::common::regressions_beside_the_source(),
        ..ProptestConfig::default()
    })]
    /// The Jacobian of the flow over one period (variational equations × saltation matrices)
    /// equals central differences of the flow, for Hertz, DMT (Kelvin–Voigt tangent coordinates),
    /// the electrostatic law, JKR (the force jumps where the neck forms and breaks), the
    /// capillary meniscus (jumps where it forms and ruptures, a kink at V_T = 0 inside its
    /// region), the SLS sample (an internal state; its guard over the recovering surface) and
    /// the impact law, each from the same random starts.
    #[test]
    fn variational_jacobian_matches_finite_differences(
        a1 in -0.05f64..0.05,
        v1 in -0.3f64..0.3,
        a2 in -0.003f64..0.003,
    ) {
        for (law, modes, omega, gap) in [
            (ContactLaw::Hertz, 2, 2.8, 0.0),
            (DMT, 2, 2.8, 0.0),
            (ES, 2, 2.8, 0.0),
            (JKR, 2, 2.8, 0.0),
            (CAP, 2, 2.8, 0.0),
            (SLS, 2, 2.8, 0.0),
            (ContactLaw::Impact { restitution: 0.5 }, 1, 3.0, 0.05),
        ] {
            let p = Params { modes, omega, alpha5: gap, contact_law: law, ..Params::default() };
            let m = CantileverModel::new(&p).unwrap();
            let mut z0 = DVector::zeros(m.dim());
            z0[0] = 0.1 + a1;
            z0[modes] = v1;
            if modes > 1 {
                z0[1] = a2;
            }
            if law.internal_states() > 0 {
                // the SLS sample dented by a previous tap: the surface recovering
                z0[2 * modes] = 0.05 + a1;
            }
            let t1 = m.period();
            let mut it = build(&m, opts(IntegratorKind::Adaptive, 1e-13), 0.0, &z0).unwrap();
            let map = flow(it.as_mut(), 0.0, &z0, t1, None, true).unwrap();
            // near grazing the flow is not differentiable enough for central differences
            if map.grazing_distance <= 1e-2 {
                continue;
            }
            // the capillary force's kink at V_T = 0 lies inside a step: the flow's error at
            // the tolerance then varies unevenly with the start, by up to ~1e-9, which one
            // difference step magnifies unevenly too (eps = 1e-5: up to 7.0e-5 over 177 random
            // starts; 5.0e-5 at a1 = 0.0366, v1 = −0.188, a2 = 8.0e-4, where 3e-5 gives 1.4e-6).
            // The capillary Jacobian is therefore held against differences at three steps, the
            // closest counting (worst 2.9e-6 over the same 177 starts): a wrong entry disagrees
            // at every step
            let steps: &[f64] =
                if matches!(law, ContactLaw::Capillary { .. }) { &[3e-5, 1e-5, 3e-6] } else { &[1e-6] };
            let err = steps
                .iter()
                .map(|&eps| {
                    let fd = fd_flow_jacobian(&m, &z0, t1, eps);
                    (&map.jacobian - &fd).amax() / (1.0 + fd.amax())
                })
                .fold(f64::INFINITY, f64::min);
            prop_assert!(err < 1e-5, "{law}: relative error {err:e}, {} events", map.switchings);
        }
    }
}

// ------------------------------------------------------------------------- impact law

struct Case {
    law: ContactLaw,
    modes: usize,
    omega: f64,
    gap: f64,
    period: usize,
}

/// Steady state, shooting + Floquet multipliers (against finite differences of the map), a short
/// continuation (every point a fixed point of the map) and Lyapunov exponents (λ₁ against
/// ln|μ₁|/(nT)) for each law.
#[test]
fn every_analysis_on_every_law() {
    let cases = [
        Case {
            law: ContactLaw::Linear,
            modes: 3,
            omega: 2.8,
            gap: 0.0,
            period: 2,
        },
        Case {
            law: ContactLaw::Hertz,
            modes: 2,
            omega: 2.8,
            gap: 0.0,
            period: 1,
        },
        Case {
            law: DMT,
            modes: 2,
            omega: 2.8,
            gap: 0.0,
            period: 1,
        },
        Case {
            law: ES,
            modes: 2,
            omega: 2.8,
            gap: 0.0,
            period: 1,
        },
        Case {
            law: JKR,
            modes: 2,
            omega: 2.8,
            gap: 0.0,
            period: 1,
        },
        Case {
            law: CAP,
            modes: 2,
            omega: 2.8,
            gap: 0.0,
            period: 1,
        },
        Case {
            law: SLS,
            modes: 2,
            omega: 3.0,
            gap: 0.0,
            period: 1,
        },
        Case {
            law: ContactLaw::Impact { restitution: 0.5 },
            modes: 1,
            omega: 3.0,
            gap: 0.05,
            period: 1,
        },
    ];
    for c in cases {
        let p = Params {
            modes: c.modes,
            omega: c.omega,
            alpha5: c.gap,
            contact_law: c.law,
            ..Params::default()
        };
        let m = CantileverModel::new(&p).unwrap();
        let mut it = build(&m, IntegratorOptions::default(), 0.0, &m.rest()).unwrap();
        let ss = steady_state(it.as_mut(), &SteadyOptions::default()).unwrap();
        assert_eq!(
            ss.motion,
            Motion::Periodic { period: c.period },
            "{}",
            c.law
        );
        let mut it = build(&m, IntegratorOptions::default(), 0.0, &m.rest()).unwrap();
        let period = ShootingOptions::default().with_period(c.period);
        let map = &mut StroboscopicMap::new(it.as_mut(), 1);
        let o = shoot(map, ss.end_state(), &period).unwrap();
        assert!(o.stable, "{}", c.law);
        assert!((&o.state - ss.end_state()).amax() < 1e-6, "{}", c.law);
        // multipliers against a central-difference monodromy of the same map
        let mut it = build(
            &m,
            IntegratorOptions {
                tolerance: 1e-13,
                ..Default::default()
            },
            0.0,
            &m.rest(),
        )
        .unwrap();
        let dim = o.state.len();
        let eps = 1e-6;
        let mut fd = DMatrix::zeros(dim, dim);
        for k in 0..dim {
            let (mut zp, mut zm) = (o.state.clone(), o.state.clone());
            zp[k] += eps;
            zm[k] -= eps;
            let a = StroboscopicMap::new(it.as_mut(), c.period)
                .apply(&zp)
                .unwrap()
                .state;
            let b = StroboscopicMap::new(it.as_mut(), c.period)
                .apply(&zm)
                .unwrap()
                .state;
            fd.set_column(k, &((a - b) / (2.0 * eps)));
        }
        let mu_fd = floquet_multipliers(&fd);
        for (a, b) in o.multipliers.iter().zip(&mu_fd) {
            assert!(
                (a.norm() - b.norm()).abs() < 1e-5,
                "{}: |μ| {a} vs {b}",
                c.law
            );
        }
        // a short continuation in Ω: every point is a fixed point of its map
        let mut spec =
            ContinuationSpec::new(p, SweepParam::Omega, c.omega, c.omega + 0.03, c.period);
        spec.max_points = 6;
        let branch = continue_branch(&spec, &o.state, &Progress::new()).unwrap();
        assert!(branch.len() >= 3, "{}: {} points", c.law, branch.len());
        // six points do not reach Ω + 0.03: the branch says it stopped at its cap, where
        let last = branch.last().unwrap().value;
        match branch.end {
            BranchEnd::MaxPoints { value } => assert_eq!(value, last, "{}", c.law),
            BranchEnd::Range => assert!(branch.len() < 6, "{}", c.law),
            e => panic!("{}: ended by {e:?}", c.law),
        }
        for bp in &branch {
            let mb = CantileverModel::new(&p.with(SweepParam::Omega, bp.value)).unwrap();
            let mut ib = build(&mb, IntegratorOptions::default(), 0.0, &mb.rest()).unwrap();
            let back = StroboscopicMap::new(ib.as_mut(), c.period)
                .apply(&bp.section[0])
                .unwrap()
                .state;
            assert!(
                (back - &bp.section[0]).amax() < 1e-8,
                "{} at Ω = {}",
                c.law,
                bp.value
            );
        }
        // Lyapunov exponents of the stable orbit: λ₁ = ln|μ₁|/(nT)
        let l = lyapunov_spectrum(
            &m,
            &o.state,
            &LyapunovOptions {
                transient_periods: 0,
                periods: 400,
                blocks: 4,
                ..Default::default()
            },
        )
        .unwrap();
        let want = o.multipliers[0].norm().ln() / (c.period as f64 * m.period());
        assert!(l.exponents[0] < 0.0, "{}", c.law);
        assert!(
            (l.exponents[0] - want).abs() < 0.02,
            "{}: λ₁ {} vs {want}",
            c.law,
            l.exponents[0]
        );
    }
}

/// Applying the saltation matrix from its parts (R M + w (∇gᵀ M), no product when R = I) gives
/// S M with S formed ([`afmdyn::system::saltation`]), for a switching of the linear law, of
/// the Hertz law, and for an impact (R ≠ I) and a release from sticking of the impact law.
#[test]
fn saltation_parts_apply_the_saltation_matrix() {
    use afmdyn::system::{saltation, saltation_parts};
    let cases = [
        (ContactLaw::Linear, Region::Free),
        (ContactLaw::Linear, Region::Contact),
        (ContactLaw::Hertz, Region::Free),
        (ContactLaw::Impact { restitution: 0.6 }, Region::Free),
        (ContactLaw::Impact { restitution: 0.6 }, Region::Contact),
    ];
    for (law, from) in cases {
        let m = CantileverModel::new(&Params {
            contact_law: law,
            alpha6: 0.3,
            ..Params::default()
        })
        .unwrap();
        let d = m.dim();
        let (tau, z) = (
            0.7,
            DVector::from_fn(d, |i, _| 0.05 * (i as f64 + 1.0).sin()),
        );
        let (s, _) = saltation(&m, from, tau, z.as_slice());
        let parts = saltation_parts(&m, from, tau, z.as_slice());
        // `apply` skips R at a switching: the state is continuous there
        if parts.jump.kind == EventKind::Switching {
            assert_eq!(
                parts.jump.jacobian,
                DMatrix::identity(d, d),
                "{law:?} {from:?}"
            );
        }
        assert!(parts.shift.norm() > 0.0, "{law:?} {from:?}: S = R");
        let mut mm = DMatrix::from_fn(d, d, |i, j| ((i * d + j) as f64).cos());
        let want = &s * &mm;
        parts.apply(mm.as_mut_slice());
        let err = (&mm - &want).amax();
        assert!(
            err <= 1e-14 * (1.0 + want.amax()),
            "{law:?} {from:?}: {err:.2e}"
        );
    }
}

/// The continuation's work budget: a Hertz branch allowed 2 000 steps of its contact integrator
/// (Taylor series) stops after spending them (the budget is checked before each predictor step,
/// so at most one corrector's worth beyond it), names the parameter value of its last point,
/// and says what to change; the same branch with the default budget covers its range.
#[test]
fn a_branch_ends_when_its_work_budget_is_spent() {
    let p = Params {
        contact_law: ContactLaw::Hertz,
        ..Params::default()
    };
    let m = CantileverModel::new(&p.with(SweepParam::Omega, 5.0)).unwrap();
    let mut it = build(&m, IntegratorOptions::default(), 0.0, &m.rest()).unwrap();
    let map = &mut StroboscopicMap::new(it.as_mut(), 1);
    let o = shoot(map, &m.rest(), &ShootingOptions::default()).unwrap();
    let mut spec = ContinuationSpec::new(p, SweepParam::Omega, 5.0, 4.9, 1);
    let full = continue_branch(&spec, &o.state, &Progress::new()).unwrap();
    assert_eq!(full.end, BranchEnd::Range);
    assert!(full.end.warning(SweepParam::Omega, 1).is_none());
    spec.max_work = 2_000;
    let cut = continue_branch(&spec, &o.state, &Progress::new()).unwrap();
    let BranchEnd::Budget { value, steps } = cut.end else {
        panic!("ended by {:?}", cut.end);
    };
    assert!(steps > 2_000 && steps < 20_000, "{steps} steps");
    assert_eq!(value, cut.last().unwrap().value);
    assert!(
        cut.len() < full.len(),
        "{} vs {} points",
        cut.len(),
        full.len()
    );
    assert_eq!(
        cut.points[..],
        full.points[..cut.len()],
        "the same points up to the cut"
    );
    let w = cut.end.warning(SweepParam::Omega, 1).unwrap();
    assert!(
        w.contains("omega = ") && w.contains("work budget") && w.contains("--from"),
        "{w}"
    );
}

/// A split integrator reused for many runs (as shooting and continuation reuse one) forgets
/// each run's events at its reset: 4200 one-period runs of the Hertz law from the same start,
/// each with its contact (an event of the adaptive half), end as the first did (to the
/// tolerance) — the
/// chattering test (4096 events within 1e-7 of a period) would otherwise hold events of earlier
/// runs, later in τ than the new run's, and stop it.
#[test]
fn a_reused_split_integrator_forgets_the_events_of_earlier_runs() {
    let (p, m) = law_model(ContactLaw::Hertz, 1, 2.6);
    let mut it = build(&m, opts(IntegratorKind::Split, 1e-8), 0.0, &m.rest()).unwrap();
    afmdyn::integrate::advance(it.as_mut(), 20.0 * p.period()).unwrap();
    let z0 = it.state().clone();
    let mut first = None;
    for _ in 0..4200 {
        it.reset(0.0, &z0).unwrap();
        afmdyn::integrate::advance(it.as_mut(), p.period()).unwrap();
        let z = it.state().clone();
        // the same run to the tolerance (the adaptive half's first step size is the last
        // run's, so not bit for bit)
        let d = (first.get_or_insert_with(|| z.clone()).clone() - z).amax();
        assert!(d < 1e-6, "{d:e}");
    }
}

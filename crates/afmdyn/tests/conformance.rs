//! One conformance suite over every integrator × contact law pair (exact, rk4, rk4-naive,
//! adaptive, split, taylor × every law of the registry, [`afmdyn::contact::LAWS`]: linear,
//! Hertz, DMT, electrostatic, JKR, capillary, SLS, impact, and the toy law with the `toy-law`
//! feature): the support table from the laws' capabilities (every unsupported pair is refused
//! with [`SimError::Unsupported`] naming the integrator), and for every supported pair the
//! identities an integrator of the switched model must satisfy:
//!
//! * a sample out of reach: no event, the closed-form harmonic response of the free flight
//!   (`common::harmonic_response`), landing exactly on the end time;
//! * with the sample: events chaining region to region, located on their guard (V_T = 0 for a
//!   switching, to 1e-10; the impact law's release guard to 1e-7), not re-triggered;
//! * the stroboscopic state after 3 drive periods from rest agrees with the oracle, DOP853 at
//!   tolerance 1e-14 (`adaptive`), to the pair's stated tolerance;
//! * the step Jacobian (where the integrator has one: not RK4) equals central finite
//!   differences of the flow over the step;
//! * dense output at a step's end equals the state (or, at an event, the state before it);
//! * reset and replay are deterministic, bit for bit;
//! * bad starts are refused with their typed errors;
//! * the capability accessors ([`Integrator::affine`], [`Integrator::spans`]) are offered by
//!   the integrators that have them only.

use afmdyn::contact::LawGroups;
use afmdyn::galerkin::Region;
use afmdyn::integrate::{advance, build, Integrator, IntegratorKind, IntegratorOptions, Step};
use afmdyn::{CantileverModel, ContactLaw, HybridSystem, LawKind, Params, SimError};
use nalgebra::{DMatrix, DVector};

use super::common;
use common::laws::{CAP, DMT, ES, JKR, SLS};
use common::{events_until, harmonic_response};

const IMPACT: ContactLaw = ContactLaw::Impact { restitution: 0.6 };

/// The cases: every registered law, with these groups where given, else its defaults.
fn laws() -> Vec<ContactLaw> {
    let chosen = [
        ContactLaw::Linear,
        ContactLaw::Hertz,
        DMT,
        ES,
        JKR,
        CAP,
        SLS,
        IMPACT,
    ];
    LawKind::ALL
        .iter()
        .map(|&kind| {
            chosen
                .into_iter()
                .find(|law| law.kind() == kind)
                .unwrap_or_else(|| kind.with_groups(LawGroups::default()))
        })
        .collect()
}

const KINDS: [IntegratorKind; 6] = [
    IntegratorKind::Exact,
    IntegratorKind::Rk4,
    IntegratorKind::Rk4Naive,
    IntegratorKind::Adaptive,
    IntegratorKind::Split,
    IntegratorKind::Taylor,
];

/// The integrator's name in its refusal.
fn name(kind: IntegratorKind) -> &'static str {
    match kind {
        IntegratorKind::Auto => "auto",
        IntegratorKind::Exact => "exact",
        IntegratorKind::Rk4 | IntegratorKind::Rk4Naive => "rk4",
        IntegratorKind::Adaptive => "adaptive",
        IntegratorKind::Split => "split",
        IntegratorKind::Taylor => "taylor",
    }
}

/// The support table: which integrator carries which law, by the law's capabilities.
fn supported(kind: IntegratorKind, law: ContactLaw) -> bool {
    let p = Params::default();
    let (affine, impact, outside, jet, hysteretic) = (
        law.is_affine(),
        law.restitution().is_some(),
        law.acts_outside(),
        law.jet(p.alpha4, p.alpha6).is_some(),
        law.hysteresis(p.alpha4).is_some(),
    );
    // the SLS sample's internal state: the adaptive integrator only
    if law.internal_states() > 0 {
        return matches!(kind, IntegratorKind::Auto | IntegratorKind::Adaptive);
    }
    match kind {
        IntegratorKind::Auto | IntegratorKind::Adaptive => true,
        IntegratorKind::Exact => affine,
        // JKR's and the meniscus's region depends on the history (the neck, the meniscus), not
        // on the sign of V_T alone
        IntegratorKind::Rk4 | IntegratorKind::Rk4Naive => !impact && !hysteretic,
        // DMT's and the electrostatic force act in free flight; the Taylor recurrences carry
        // the laws with a piece of the jet (Hertz, DMT)
        IntegratorKind::Split => !outside,
        IntegratorKind::Taylor => jet,
    }
}

fn opts(kind: IntegratorKind, tol: f64) -> IntegratorOptions {
    IntegratorOptions {
        kind,
        steps_per_period: if matches!(kind, IntegratorKind::Rk4 | IntegratorKind::Rk4Naive) {
            4000
        } else {
            1
        },
        tolerance: tol,
        ..Default::default()
    }
}

fn model(law: ContactLaw, alpha5: Option<f64>) -> CantileverModel {
    let d = Params::default();
    CantileverModel::new(&Params {
        contact_law: law,
        alpha5: alpha5.unwrap_or(d.alpha5),
        ..d
    })
    .unwrap()
}

/// Accuracy of the state after 3 drive periods against the oracle, and of the closed-form free
/// response, per integrator (RK4: fourth order at 4000 steps per period; the others at their
/// tolerance 1e-12, exact to round-off).
fn accuracy(kind: IntegratorKind) -> f64 {
    match kind {
        IntegratorKind::Rk4 | IntegratorKind::Rk4Naive => 1e-6,
        IntegratorKind::Exact => 1e-9,
        _ => 1e-8,
    }
}

/// Accuracy of the closed-form free response after 7.3 units of τ from its start (the
/// tolerances of the partial suites this one replaced: exact 1e-12, split and Taylor 1e-11, the
/// others 1e-9).
fn free_accuracy(kind: IntegratorKind) -> f64 {
    match kind {
        IntegratorKind::Exact => 1e-12,
        IntegratorKind::Split | IntegratorKind::Taylor => 1e-11,
        _ => 1e-9,
    }
}

/// Unsupported pairs are typed refusals naming the integrator; supported ones build.
#[test]
fn the_support_table() {
    for law in laws() {
        let m = model(law, None);
        for kind in KINDS {
            let built = build(&m, opts(kind, 1e-12), 0.0, &m.rest());
            if supported(kind, law) {
                assert!(built.is_ok(), "{law} {kind:?}: {:?}", built.err());
            } else {
                assert!(
                    common::is_refusal(&built, name(kind), None),
                    "{law} {kind:?}: {:?}",
                    built.map(|_| ())
                );
            }
        }
    }
}

/// Free flight with the sample out of reach, events with it, bad starts.
#[test]
fn free_flight_events_and_bad_starts() {
    for law in laws() {
        for kind in KINDS.into_iter().filter(|&k| supported(k, law)) {
            // (a) a sample out of reach: no event, the closed-form free response, exact landing
            let m = model(common::without_attraction(law), Some(5.0));
            let start = harmonic_response(&m, Region::Free, 0.0);
            let mut it = build(&m, opts(kind, 1e-13), 0.0, &start).unwrap();
            assert!(events_until(it.as_mut(), 7.3).is_empty(), "{law} {kind:?}");
            assert_eq!(it.tau(), 7.3, "{law} {kind:?}");
            let err = (it.state() - harmonic_response(&m, Region::Free, 7.3)).amax();
            assert!(err < free_accuracy(kind), "{law} {kind:?}: {err:e}");
            // (b) with the sample: events chain region to region, sit on their guard, do not
            // re-trigger (the paper's RK4 chooses the region per stage: no located events)
            let m = model(law, None);
            let mut it = build(&m, opts(kind, 1e-12), 0.0, &m.rest()).unwrap();
            let ev = events_until(it.as_mut(), 30.0);
            assert!(ev.len() > 5, "{law} {kind:?}: {} events", ev.len());
            for w in ev.windows(2) {
                assert_eq!(w[0].to, w[1].from, "{law} {kind:?}: chained");
                if law.restitution().is_none() {
                    assert!(w[1].tau - w[0].tau > 1e-6, "{law} {kind:?}: re-triggered");
                }
            }
            if kind != IntegratorKind::Rk4Naive {
                for e in &ev {
                    let g = m.guard(e.from, e.tau, e.state.as_slice()).value;
                    let scale = if e.from == Region::Contact && law.restitution().is_some() {
                        1e-7
                    } else {
                        1e-10
                    };
                    assert!(
                        g.abs() < scale,
                        "{law} {kind:?}: guard {g:e} at {:?}",
                        e.kind
                    );
                }
            }
            // (c) bad starts are refused with their error
            let mut nan = m.rest();
            nan[1] = f64::NAN;
            assert!(
                matches!(it.reset(0.0, &nan), Err(SimError::NotFinite { .. })),
                "{law} {kind:?}"
            );
            assert!(
                matches!(
                    it.reset(0.0, &DVector::zeros(3)),
                    Err(SimError::StateLength { .. })
                ),
                "{law} {kind:?}"
            );
            assert!(
                matches!(
                    it.reset(f64::NAN, &m.rest()),
                    Err(SimError::NotFinite { .. })
                ),
                "{law} {kind:?}"
            );
        }
    }
}

/// The stroboscopic state after 3 drive periods from rest against DOP853 at 1e-14.
#[test]
fn stroboscopic_state_agrees_with_the_oracle() {
    for law in laws() {
        let m = model(law, None);
        let t = 3.0 * m.period();
        let mut oracle = build(&m, opts(IntegratorKind::Adaptive, 1e-14), 0.0, &m.rest()).unwrap();
        advance(oracle.as_mut(), t).unwrap();
        for kind in KINDS.into_iter().filter(|&k| supported(k, law)) {
            let mut it = build(&m, opts(kind, 1e-12), 0.0, &m.rest()).unwrap();
            advance(it.as_mut(), t).unwrap();
            let d = (it.state() - oracle.state()).amax();
            eprintln!("{law} {kind:?}: {d:.2e}");
            let tol = if kind == IntegratorKind::Rk4Naive {
                // the region chosen per stage: first order at the switchings
                1e-3
            } else if law.restitution().is_some() {
                // low-velocity impacts amplify differences (the square-root singularity of
                // the grazing impact, `tests/laws.rs`)
                10.0 * accuracy(kind)
            } else {
                accuracy(kind)
            };
            assert!(d < tol, "{law} {kind:?}: {d:e}");
        }
    }
}

/// Steps from rest over `periods` drive periods: (step, state before, state after).
fn steps(it: &mut dyn Integrator, t_end: f64) -> Vec<(Step, DVector<f64>, DVector<f64>)> {
    let mut out = Vec::new();
    while it.tau() < t_end {
        let before = it.state().clone();
        let s = it.step(t_end).unwrap();
        out.push((s, before, it.state().clone()));
    }
    out
}

/// Dense output at a step's end is the state there (before the jump of an event that ends it);
/// a run replayed by a new integrator gives the same steps and states bit for bit, and by the
/// same integrator after a reset the same end state.
#[test]
fn dense_output_and_replay() {
    for law in laws() {
        let m = model(law, None);
        let t = 2.0 * m.period();
        for kind in KINDS.into_iter().filter(|&k| supported(k, law)) {
            let mut it = build(&m, opts(kind, 1e-12), 0.0, &m.rest()).unwrap();
            let first = steps(it.as_mut(), t);
            it.reset(0.0, &m.rest()).unwrap();
            let mut checked = 0;
            while it.tau() < t {
                let s = it.step(t).unwrap();
                if s.tau1 <= s.tau0 {
                    continue;
                }
                let end = match &s.event {
                    Some(e) => e.state.clone(),
                    None => it.state().clone(),
                };
                let dense = it.dense_state(s.tau1);
                let scale = 1.0 + end.amax();
                let d = (&dense - &end).amax();
                assert!(d <= 1e-9 * scale, "{law} {kind:?}: dense state {d:e}");
                let w = it.dense_tip(s.tau1)[0];
                let d = (w - m.w_tip(&end)).abs();
                assert!(d <= 1e-9 * scale, "{law} {kind:?}: dense tip {d:e}");
                checked += 1;
            }
            assert!(checked > 2, "{law} {kind:?}");
            // replay: a second integrator takes the same steps bit for bit; the first one,
            // reset, ends in the same state to its accuracy (an adaptive integrator starts
            // from the step size it had reached)
            let end = it.state().clone();
            let mut again = build(&m, opts(kind, 1e-12), 0.0, &m.rest()).unwrap();
            assert_eq!(first, steps(again.as_mut(), t), "{law} {kind:?}: replay");
            let d = (&end - &first.last().unwrap().2).amax();
            assert!(d < accuracy(kind), "{law} {kind:?}: reset and replay {d:e}");
        }
    }
}

/// The step Jacobian ∂z(τ1)/∂z(τ0) against central differences of the flow over the step, for
/// steps without an event, in both regions where the run has both (RK4 has no step Jacobian:
/// refused with [`SimError::Unsupported`]).
#[test]
fn step_jacobians_match_finite_differences() {
    for law in laws() {
        let m = model(law, None);
        let t = 2.0 * m.period();
        for kind in KINDS.into_iter().filter(|&k| supported(k, law)) {
            let mut it = build(&m, opts(kind, 1e-13), 0.0, &m.rest()).unwrap();
            it.set_variational(true);
            if matches!(kind, IntegratorKind::Rk4 | IntegratorKind::Rk4Naive) {
                it.step(t).unwrap();
                assert!(
                    matches!(it.last_step_jacobian(), Err(SimError::Unsupported { .. })),
                    "{law} {kind:?}"
                );
                continue;
            }
            let mut done = [false; 2];
            while it.tau() < t && done != [true, true] {
                let z0 = it.state().clone();
                let s = it.step(t).unwrap();
                let len = s.tau1 - s.tau0;
                // a step of some length, clear of events, not starting on the guard (the rest
                // state at τ = 0 has V_T = α5 = 0: the flow is not differentiable there), whose
                // region is not done yet
                let grazing_start = m.v_t(s.tau0, &z0).abs() < 1e-6;
                if s.event.is_some() || len < 1e-3 || grazing_start || done[s.region.index()] {
                    continue;
                }
                let j = it.last_step_jacobian().unwrap();
                let (tau0, tau1, after) = (s.tau0, s.tau1, it.state().clone());
                let dim = z0.len();
                let mut fd = DMatrix::zeros(dim, dim);
                let mut probe = build(&m, opts(kind, 1e-13), 0.0, &m.rest()).unwrap();
                let mut clear = true;
                for i in 0..dim {
                    let h = 1e-6 * (1.0 + z0[i].abs());
                    let mut flow = |sign: f64| {
                        let mut z = z0.clone();
                        z[i] += sign * h;
                        probe.reset(tau0, &z).unwrap();
                        let r = probe.region();
                        let ev = events_until(probe.as_mut(), tau1);
                        (probe.state().clone(), ev.is_empty() && r == s.region)
                    };
                    let ((zp, okp), (zm, okm)) = (flow(1.0), flow(-1.0));
                    clear &= okp && okm;
                    fd.set_column(i, &((zp - zm) / (2.0 * h)));
                }
                if !clear {
                    continue; // a perturbed start crossed the guard
                }
                let err = (&j - &fd).amax() / j.amax().max(1.0);
                eprintln!("{law} {kind:?} {:?}: {err:.2e} [{tau0}, {tau1}]", s.region);
                assert!(err < 1e-5, "{law} {kind:?} {:?}: {err:e}", s.region);
                // the state after the step is the flow's
                assert!((&after - it.state()).amax() == 0.0);
                done[s.region.index()] = true;
            }
            assert!(done[0], "{law} {kind:?}: no free step checked");
        }
    }
}

/// The capability accessors: region transitions and parameter derivatives for the
/// integrators of affine regions (exact; split's free flight), spans for those that keep their
/// own representation of the state (exact, split), none for the others.
#[test]
fn capabilities_where_they_are() {
    for law in laws() {
        let m = model(law, None);
        for kind in KINDS.into_iter().filter(|&k| supported(k, law)) {
            let mut it = build(&m, opts(kind, 1e-12), 0.0, &m.rest()).unwrap();
            let own = matches!(kind, IntegratorKind::Exact | IntegratorKind::Split);
            assert_eq!(it.affine().is_some(), own, "{law} {kind:?}: affine");
            assert_eq!(it.spans().is_some(), own, "{law} {kind:?}: spans");
            if let Some(a) = it.affine() {
                assert!(a.has_region_transition(Region::Free), "{law} {kind:?}");
                assert_eq!(
                    a.has_region_transition(Region::Contact),
                    kind == IntegratorKind::Exact,
                    "{law} {kind:?}"
                );
            }
        }
    }
}

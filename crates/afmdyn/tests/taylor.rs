//! The Taylor integrator (`integrate/taylor/`) against the adaptive DOP853 integrator at a
//! tighter tolerance (1e-14), an independent method: the same events and states over 30 drive
//! periods, the same period-1 orbits and monodromy matrices (its variational equations in the
//! regularised contact time against DOP853's in τ, saltation at the switchings), for the
//! point-mass DMT probe and the beam (N = 3) with the Hertz and DMT laws, DMT with its
//! Kelvin–Voigt term; the conformance suite of every integrator; its refusals.

use afmdyn::analysis::shooting::{shoot, ShootingOptions};
use afmdyn::galerkin::Region;
use afmdyn::integrate::{build, IntegratorKind, IntegratorOptions};
use afmdyn::maps::StroboscopicMap;
use afmdyn::request::analyses::OrbitRequest;
use afmdyn::{CantileverModel, ContactLaw, Params};

use super::common;
use common::{against_adaptive_oracle, events_until, harmonic_response};

const DMT: ContactLaw = ContactLaw::Dmt {
    hamaker: 1e-5,
    intermolecular_distance: 0.01,
};

fn opts(kind: IntegratorKind, tol: f64) -> IntegratorOptions {
    IntegratorOptions {
        kind,
        steps_per_period: 1,
        tolerance: tol,
        ..IntegratorOptions::default()
    }
}

fn probe_model() -> CantileverModel {
    let probe = afmdyn::probe::Probe::parse(
        include_str!("../../../examples/probe-point-mass-dmt.toml"),
        "examples/probe-point-mass-dmt.toml",
    )
    .unwrap();
    CantileverModel::new(&probe.params).unwrap()
}

fn beam(law: ContactLaw, alpha6: f64, omega: f64) -> CantileverModel {
    CantileverModel::new(&Params {
        modes: 3,
        omega,
        alpha6,
        contact_law: law,
        ..Params::default()
    })
    .unwrap()
}

/// The models of these tests: the point-mass DMT probe, the beam (N = 3) with Hertz (α6 = 0.2,
/// the default damper), DMT without and with Kelvin–Voigt damping.
fn models() -> Vec<(&'static str, CantileverModel)> {
    vec![
        ("point-mass dmt probe", probe_model()),
        ("beam hertz", beam(ContactLaw::Hertz, 0.2, 2.8)),
        ("beam dmt", beam(DMT, 0.0, 2.6)),
        ("beam dmt kelvin-voigt", beam(DMT, 0.2, 2.8)),
    ]
}

/// 30 drive periods from the steady state `afmdyn orbit` starts from: the same switchings
/// (kind, regions, time to 1e-8) and the same final state (to 1e-8) as DOP853 at 1e-14, and a
/// final state as accurate as DOP853's at the same tolerance 1e-12 (within a factor of 10).
#[test]
fn taylor_agrees_with_the_adaptive_oracle() {
    for (name, m) in models() {
        let c = against_adaptive_oracle(&m, IntegratorKind::Taylor, 1e-12);
        let (worst, d, d_dop) = (c.worst_event, c.state, c.state_dop853);
        eprintln!("{name}: events within {worst:e}, final state within {d:e} (DOP853 {d_dop:e})");
        assert!(c.events >= 20, "{name}: {} events", c.events);
        assert!(worst < 1e-8, "{name}: events differ by {worst:e}");
        assert!(d < 1e-8, "{name}: final state differs by {d:e}");
        // the tolerance means what it means for DOP853, within a factor of 10
        assert!(
            d <= 10.0 * d_dop.max(1e-12),
            "{name}: {d:e} against DOP853's {d_dop:e} at the same tolerance"
        );
    }
}

/// The period-1 orbits by Newton shooting: the state to 1e-8 and the monodromy matrix (the
/// Taylor integrator's variational equations, in σ through the contact) to 1e-7 relative of
/// DOP853's at 1e-14, so the Floquet multipliers agree.
#[test]
fn taylor_orbits_and_monodromy_agree_with_the_adaptive_oracle() {
    for (name, m) in models() {
        let (guess, _) = OrbitRequest::default().start.guess(&m).unwrap();
        let orbit = |kind, tol| {
            let mut it = build(&m, opts(kind, tol), 0.0, &m.rest()).unwrap();
            let map = &mut StroboscopicMap::new(it.as_mut(), 1);
            shoot(map, &guess, &ShootingOptions::default())
        };
        let (Ok(a), Ok(b)) = (
            orbit(IntegratorKind::Taylor, 1e-12),
            orbit(IntegratorKind::Adaptive, 1e-14),
        ) else {
            panic!("{name}: no period-1 orbit");
        };
        assert!(a.switchings >= 1, "{name}: the orbit touches the sample");
        let d = (&a.state - &b.state).amax();
        let md = (&a.monodromy - &b.monodromy).amax() / b.monodromy.amax();
        eprintln!("{name}: orbit within {d:e}, monodromy within {md:e} relative");
        assert!(d < 1e-8, "{name}: orbit states differ by {d:e}");
        assert!(md < 1e-7, "{name}: monodromies differ by {md:e} relative");
        for (x, y) in a.multipliers.iter().zip(&b.multipliers) {
            assert!((x - y).norm() < 1e-7, "{name}: multiplier {x} vs {y}");
        }
    }
}

/// A grazing contact: the free periodic orbit V_T = α5 + R cos(Ωτ − φ) (Hertz law, the sample
/// placed so that the tip dips ε below it, ε = 1e-6 and 1e-10) enters contact within a tenth of
/// the dip's width of where the closed-form orbit crosses V_T = 0, and leaves it again; the
/// contact of the regularised time neither sticks nor misses the dip.
#[test]
fn a_grazing_contact_is_entered_and_left() {
    let p0 = Params {
        alpha5: 10.0,
        contact_law: ContactLaw::Hertz,
        ..Params::default()
    };
    let m0 = CantileverModel::new(&p0).unwrap();
    // the free orbit's lowest V_T and its time, from the closed form (golden-section search)
    let v = |t: f64| m0.v_t(t, &harmonic_response(&m0, Region::Free, t)) - 10.0;
    let n = 2048;
    let dt = p0.period() / n as f64;
    let k = (0..n)
        .min_by(|&i, &j| v(i as f64 * dt).total_cmp(&v(j as f64 * dt)))
        .unwrap();
    let (mut a, mut b) = (k as f64 * dt - dt, k as f64 * dt + dt);
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..200 {
        let (c, d) = (b - g * (b - a), a + g * (b - a));
        if v(c) < v(d) {
            b = d;
        } else {
            a = c;
        }
    }
    let t_min = 0.5 * (a + b);
    let r_amp = -v(t_min);
    for eps in [1e-6, 1e-10] {
        let p = Params {
            alpha5: r_amp - eps,
            ..p0
        };
        let m = CantileverModel::new(&p).unwrap();
        let z0 = harmonic_response(&m, Region::Free, 0.0);
        let mut it = build(&m, opts(IntegratorKind::Taylor, 1e-12), 0.0, &z0).unwrap();
        let ev = events_until(it.as_mut(), p.period());
        let curvature = p.omega * p.omega * r_amp;
        let width = 2.0 * (2.0 * eps / curvature).sqrt();
        assert!(ev.len() >= 2, "eps = {eps}: {} events", ev.len());
        assert_eq!((ev[0].to, ev[1].to), (Region::Contact, Region::Free));
        let enter = t_min - 0.5 * width;
        assert!(
            (ev[0].tau - enter).abs() < 0.1 * width,
            "eps = {eps}: enters at {} (closed form {enter})",
            ev[0].tau
        );
        assert!(
            ev[1].tau > ev[0].tau && ev[1].tau - ev[0].tau < 2.0 * width,
            "eps = {eps}: leaves at {}",
            ev[1].tau
        );
    }
}

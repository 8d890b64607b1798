//! Trajectory engine (the conformance suite of every integrator × law is tests/conformance.rs):
//! the exact propagator against independent references (closed-form harmonic response, matrix
//! exponential + bisection, the DOP853 oracle), grazing detection, no re-trigger, energy
//! balance, RK4 order, bad input.

use afmdyn::galerkin::Region;
use afmdyn::integrate::exact::ExactPropagator;
use afmdyn::integrate::{advance_dyn, build, Integrator, IntegratorKind, IntegratorOptions};
use afmdyn::trajectory::{record, RecordSpec};

use super::common;
use afmdyn::{CantileverModel, Params, SimError};
use common::{events_until, harmonic_response};
use nalgebra::DVector;

fn options(kind: IntegratorKind) -> IntegratorOptions {
    IntegratorOptions {
        kind,
        steps_per_period: if matches!(kind, IntegratorKind::Rk4 | IntegratorKind::Rk4Naive) {
            4000
        } else {
            1
        },
        tolerance: 1e-13,
        ..Default::default()
    }
}

fn max_diff(a: &DVector<f64>, b: &DVector<f64>) -> f64 {
    (a - b).amax()
}

// The conformance checks of every integrator × law: tests/conformance.rs.

// ---------------------------------------------------------------- exact propagator

#[test]
fn exact_agrees_with_the_dop853_oracle_over_many_contacts() {
    let m = CantileverModel::new(&Params::default()).unwrap();
    let mut ex = build(&m, options(IntegratorKind::Exact), 0.0, &m.rest()).unwrap();
    let tight = IntegratorOptions {
        tolerance: 1e-14,
        ..options(IntegratorKind::Adaptive)
    };
    let mut ad = build(&m, tight, 0.0, &m.rest()).unwrap();
    let e1 = events_until(ex.as_mut(), 40.0);
    let e2 = events_until(ad.as_mut(), 40.0);
    assert!(e1.len() >= 30, "{} switchings", e1.len());
    assert_eq!(e1.len(), e2.len());
    for (a, b) in e1.iter().zip(&e2) {
        assert!(
            (a.tau - b.tau).abs() < 1e-9,
            "switching at {} vs {}",
            a.tau,
            b.tau
        );
    }
    let d = max_diff(ex.state(), ad.state());
    assert!(d < 1e-9, "state at τ = 40 differs by {d}");
}

#[test]
fn switching_times_match_bisection_on_the_matrix_exponential() {
    let m = CantileverModel::new(&Params::default()).unwrap();
    let mut ex = build(&m, options(IntegratorKind::Exact), 0.0, &m.rest()).unwrap();
    let ev = events_until(ex.as_mut(), 40.0);
    let mut start = (0.0, m.rest(), Region::Contact); // V_T(0) = 0 moving up: the run starts free
    start.2 = Region::Free;
    for e in &ev {
        let (t0, z0, r) = (&start.0, &start.1, start.2);
        assert_eq!(e.from, r);
        // independent solution z(τ) = z_p(τ) + expm(A (τ − τ0)) (z0 − z_p(τ0))
        let a = &m.dynamics(r).a;
        let dz0 = z0 - harmonic_response(&m, r, *t0);
        let v = |tau: f64| {
            let z = harmonic_response(&m, r, tau) + (a * (tau - t0)).exp() * &dz0;
            let g = m.v_t(tau, &z);
            if r == Region::Free {
                g
            } else {
                -g
            }
        };
        // first sign change after τ0 on a fine scan, then bisection to round-off
        let mut lo = t0 + 1e-9;
        let mut hi = lo;
        while v(hi) > 0.0 {
            lo = hi;
            hi += 1e-3;
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if v(mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi - lo < 1e-15 {
                break;
            }
        }
        assert!(
            (e.tau - lo).abs() < 1e-12,
            "switching at {} vs bisection {}",
            e.tau,
            lo
        );
        start = (e.tau, e.state.clone(), e.to);
    }
    assert!(ev.len() > 15);
}

#[test]
fn grazing_dip_inside_one_substep_is_found() {
    // free periodic orbit V_T = α5 + R cos(Ωτ − φ); put α5 = R − ε so that the tip dips below the
    // sample by ε for a sliver much shorter than one sub-step
    for eps in [1e-7, 1e-11] {
        let p0 = Params {
            alpha5: 10.0,
            ..Params::default()
        };
        let m0 = CantileverModel::new(&p0).unwrap();
        let n = 4096;
        let tau_grid: Vec<f64> = (0..n).map(|k| p0.period() * k as f64 / n as f64).collect();
        let vt: Vec<f64> = tau_grid
            .iter()
            .map(|&t| m0.v_t(t, &harmonic_response(&m0, Region::Free, t)) - 10.0)
            .collect();
        let (kmin, rmin) =
            vt.iter().enumerate().fold(
                (0, f64::INFINITY),
                |b, (k, &v)| if v < b.1 { (k, v) } else { b },
            );
        // refine the minimum of the harmonic by a parabola through three samples
        let (a, b, c) = (vt[(kmin + n - 1) % n], vt[kmin], vt[(kmin + 1) % n]);
        let dt = p0.period() / n as f64;
        let shift = 0.5 * (a - c) / (a - 2.0 * b + c);
        let t_min = tau_grid[kmin] + shift * dt;
        let r_amp = -(b - 0.25 * (a - c) * shift);
        let _ = rmin;
        let p = Params {
            alpha5: r_amp - eps,
            ..p0
        };
        let m = CantileverModel::new(&p).unwrap();
        let z0 = harmonic_response(&m, Region::Free, 0.0);
        let mut ex = ExactPropagator::new(&m, 1);
        ex.reset(0.0, &z0).unwrap();
        let h = p.period() / ex.steps_per_period() as f64;
        let curvature = p.omega * p.omega * r_amp;
        let width = 2.0 * (2.0 * eps / curvature).sqrt();
        assert!(
            width < 0.05 * h,
            "the dip ({width}) must be far shorter than a sub-step ({h})"
        );
        let ev = events_until(&mut ex, p.period());
        assert!(!ev.is_empty(), "eps = {eps}: grazing contact missed");
        let first = &ev[0];
        assert_eq!(first.to, Region::Contact);
        assert!(
            (first.tau - (t_min - 0.5 * width)).abs() < 0.1 * width + 1e-9,
            "enters at {} (dip at {t_min})",
            first.tau
        );
        assert!(
            ev.len() >= 2 && ev[1].to == Region::Free,
            "and leaves again"
        );
    }
}

#[test]
fn energy_balance_closes_to_round_off() {
    let m = CantileverModel::new(&Params::default()).unwrap();
    let mut it = build(&m, options(IntegratorKind::Exact), 0.0, &m.rest()).unwrap();
    let tr = record(
        it.as_mut(),
        &RecordSpec {
            transient_periods: 3.0,
            record_tau: 10.0 * m.period(),
            samples_per_period: 0,
            energy: true,
            body_contact: true,
        },
    )
    .unwrap();
    assert_eq!(tr.energy.len(), 10);
    for e in &tr.energy {
        let scale = e.base_work.abs().max(e.e_start.abs()).max(1e-3);
        assert!(
            e.residual().abs() < 1e-12 * scale,
            "residual {} (scale {scale})",
            e.residual()
        );
        assert!(e.contact_dissipation > 0.0 && e.beam_dissipation > 0.0);
    }
    assert!(!tr.body_contact, "default set: only the tip touches");
}

#[test]
fn never_contacting_run_is_the_closed_form_harmonic_response() {
    let p = Params {
        alpha5: 3.0,
        modes: 5,
        ..Params::default()
    };
    let m = CantileverModel::new(&p).unwrap();
    let mut it = build(
        &m,
        options(IntegratorKind::Exact),
        0.0,
        &harmonic_response(&m, Region::Free, 0.0),
    )
    .unwrap();
    let mut worst: f64 = 0.0;
    advance_dyn(it.as_mut(), 20.0 * p.period(), &mut |it, _, _| {
        let want = harmonic_response(it.system().cantilever().unwrap(), Region::Free, it.tau());
        worst = worst.max(max_diff(it.state(), &want));
        Ok(())
    })
    .unwrap();
    assert!(worst < 1e-11, "worst deviation {worst}");
}

#[test]
fn rk4_error_falls_as_h_to_the_fourth_without_contact() {
    let p = Params {
        alpha5: 5.0,
        ..Params::default()
    };
    let m = CantileverModel::new(&p).unwrap();
    let z0 = DVector::from_vec(vec![0.3, -0.01, 0.001, 0.0, 0.2, 0.0]);
    let mut ex = build(&m, options(IntegratorKind::Exact), 0.0, &z0).unwrap();
    advance_dyn(ex.as_mut(), 10.0, &mut |_, _, _| Ok(())).unwrap();
    let err = |steps: usize| {
        let mut rk = build(
            &m,
            IntegratorOptions {
                kind: IntegratorKind::Rk4,
                steps_per_period: steps,
                tolerance: 1e-12, // ignored by RK4, but in range (issue 42)
                ..Default::default()
            },
            0.0,
            &z0,
        )
        .unwrap();
        advance_dyn(rk.as_mut(), 10.0, &mut |_, _, _| Ok(())).unwrap();
        max_diff(rk.state(), ex.state())
    };
    let (e1, e2, e3) = (err(300), err(600), err(1200));
    for (a, b) in [(e1, e2), (e2, e3)] {
        let ratio = a / b;
        assert!(
            (13.0..19.0).contains(&ratio),
            "error ratio {ratio} ({a} → {b}), expected 16"
        );
    }
}

#[test]
fn bad_run_lengths_are_rejected() {
    let m = CantileverModel::new(&Params::default()).unwrap();
    let mut it = build(&m, options(IntegratorKind::Exact), 0.0, &m.rest()).unwrap();
    let spec = |t: f64, r: f64| RecordSpec {
        transient_periods: t,
        record_tau: r,
        samples_per_period: 10,
        energy: false,
        body_contact: false,
    };
    assert!(matches!(
        record(it.as_mut(), &spec(0.0, -1.0)),
        Err(SimError::OutOfRange {
            name: "record_tau",
            ..
        })
    ));
    assert!(matches!(
        record(it.as_mut(), &spec(-1.0, 1.0)),
        Err(SimError::OutOfRange {
            name: "transient_periods",
            ..
        })
    ));
    assert!(matches!(
        record(it.as_mut(), &spec(0.0, f64::NAN)),
        Err(SimError::NotFinite { .. })
    ));
    assert!(matches!(
        m.state_from(&[0.0; 2], &[0.0; 3]),
        Err(SimError::StateLength {
            expected: 3,
            got: 2,
            ..
        })
    ));
    assert!(matches!(
        build(
            &m,
            IntegratorOptions {
                steps_per_period: 0,
                ..options(IntegratorKind::Rk4)
            },
            0.0,
            &m.rest()
        ),
        Err(SimError::OutOfRange { .. })
    ));
}

#[test]
fn undamped_resonance_is_an_error_not_a_panic() {
    // α3 = α6 = 0 and Ω exactly at the first free natural frequency: no periodic forced response
    let p0 = Params {
        alpha3: 0.0,
        alpha6: 0.0,
        ..Params::default()
    };
    let (free, _) = afmdyn::eigen::spectrum(&p0).unwrap();
    let p = Params {
        omega: free.omega[0],
        ..p0
    };
    let m = CantileverModel::new(&p).unwrap();
    let r = build(&m, options(IntegratorKind::Exact), 0.0, &m.rest());
    assert!(
        matches!(r, Err(SimError::OutOfRange { name: "omega", .. })),
        "{:?}",
        r.err()
    );
}

#[test]
fn a_tip_resting_on_the_sample_stays_without_chattering() {
    // α2 = α5 = 0 from rest: V_T = dV_T/dτ = 0 and the contact force vanishes, so the exact
    // solution is rest; the switching test must not flip between the regions forever
    let m = CantileverModel::new(&Params {
        alpha2: 0.0,
        ..Params::default()
    })
    .unwrap();
    let mut it = build(&m, options(IntegratorKind::Exact), 0.0, &m.rest()).unwrap();
    let ev = events_until(it.as_mut(), 5.0 * m.period());
    assert!(ev.is_empty(), "{} switchings", ev.len());
    assert_eq!(it.state().amax(), 0.0);
}

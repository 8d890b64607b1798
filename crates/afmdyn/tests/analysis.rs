//! Steady states on the stroboscopic map: period detection, a period-2 orbit checked with the
//! independent DOP853 oracle, attractor clustering, sweeps.

use afmdyn::analysis::attractors::{find_attractors, same_attractor, AttractorSpec};
use afmdyn::analysis::bifurcation::{run_sweep, Branch, Resume, SweepSpec};
use afmdyn::analysis::period::{detect_period, minimal_divisor, MERGE_FACTOR};
use afmdyn::analysis::progress::Progress;
use afmdyn::analysis::steady::{steady_state, Motion, SteadyOptions};
use afmdyn::integrate::{advance_dyn, build, IntegratorKind, IntegratorOptions};
use afmdyn::{CantileverModel, Params, SweepParam};
use nalgebra::DVector;
use std::sync::Mutex;

fn v(x: f64, y: f64) -> DVector<f64> {
    DVector::from_vec(vec![x, y])
}

#[test]
fn period_detection_on_constructed_sequences() {
    let cycle = |n: usize, len: usize| -> Vec<DVector<f64>> {
        (0..len)
            .map(|k| v((k % n) as f64, ((k % n) * (k % n)) as f64))
            .collect()
    };
    for n in [1, 2, 3, 11, 21, 28, 64] {
        assert_eq!(
            detect_period(&cycle(n, 2 * n + 3), 1e-10, 64),
            Some(n),
            "period {n}"
        );
    }
    // a period-4 cycle is not reported as period 2 even though every other point matches half
    let p4: Vec<_> = (0..12)
        .map(|k| v([0.0, 1.0, 0.0, 2.0][k % 4], 0.0))
        .collect();
    assert_eq!(detect_period(&p4, 1e-10, 64), Some(4));
    // not enough history for a period-5 decision
    assert_eq!(detect_period(&cycle(5, 9), 1e-10, 64), None);
    // a converging (not yet converged) sequence and an irrational rotation are not periodic
    let conv: Vec<_> = (0..40).map(|k| v(0.5f64.powi(k), 1.0)).collect();
    assert_eq!(detect_period(&conv[..10], 1e-10, 64), None);
    assert_eq!(detect_period(&conv, 1e-10, 64), Some(1));
    let rot: Vec<_> = (0..200)
        .map(|k| v((k as f64 * 2f64.sqrt()).sin(), 0.0))
        .collect();
    assert_eq!(detect_period(&rot, 1e-8, 64), None);
    // tolerance is relative to 1 + |P|
    let big: Vec<_> = (0..6)
        .map(|k| v(1e6 + 1e-4 * (k % 2) as f64, 0.0))
        .collect();
    assert_eq!(detect_period(&big, 1e-9, 64), Some(1));
}

#[test]
fn a_slowly_rotating_focus_is_period_one_not_four() {
    // returns spiral into a fixed point, turning by 90° per period: P_{k+4} ≈ P_k long before
    // P_{k+1} ≈ P_k
    let mu = 0.999f64;
    let seq: Vec<DVector<f64>> = (0..400)
        .map(|k| {
            let r = 1e-6 * mu.powi(k);
            let a = k as f64 * std::f64::consts::FRAC_PI_2;
            v(1.0 + r * a.cos(), r * a.sin())
        })
        .collect();
    let first = (8..seq.len())
        .find_map(|k| detect_period(&seq[..k], 1e-8, 64).map(|n| (k, n)))
        .unwrap();
    assert_eq!(first.1, 4, "the naive test is fooled");
    let (k, n) = first;
    assert_eq!(minimal_divisor(&seq[..k + 8], n, 1e-8 * MERGE_FACTOR), 1);
    // a genuine period-4 cycle is not merged
    let p4: Vec<_> = (0..20)
        .map(|k| v([0.0, 1.0, 0.0, 2.0][k % 4], 0.0))
        .collect();
    assert_eq!(minimal_divisor(&p4, 4, 1e-8 * MERGE_FACTOR), 4);
}

#[test]
fn period_two_orbit_at_omega_2_8_is_confirmed_by_the_oracle() {
    let p = Params {
        omega: 2.8,
        ..Params::default()
    };
    let m = CantileverModel::new(&p).unwrap();
    let mut it = build(&m, IntegratorOptions::default(), 0.0, &m.rest()).unwrap();
    let s = steady_state(it.as_mut(), &SteadyOptions::default()).unwrap();
    assert_eq!(s.motion, Motion::Periodic { period: 2 });
    assert_eq!(s.poincare.len(), 2);
    // independent check with DOP853: two periods return to the point, one does not
    let z = s.poincare[0].state.clone();
    let t0 = s.poincare[0].tau;
    let oracle = IntegratorOptions {
        kind: IntegratorKind::Adaptive,
        steps_per_period: 1,
        tolerance: 1e-13,
        ..IntegratorOptions::default()
    };
    let mut ad = build(&m, oracle, t0, &z).unwrap();
    advance_dyn(ad.as_mut(), t0 + p.period(), &mut |_, _, _| Ok(())).unwrap();
    let one = ad.state().clone();
    advance_dyn(ad.as_mut(), t0 + 2.0 * p.period(), &mut |_, _, _| Ok(())).unwrap();
    assert!(
        (ad.state() - &z).amax() < 1e-7,
        "P² z = z: {}",
        (ad.state() - &z).amax()
    );
    assert!((&one - &z).amax() > 1e-3, "P z ≠ z");
    assert!((&one - &s.poincare[1].state).amax() < 1e-7);
    assert!(s.stats.contacts_per_period > 0.0 && s.stats.contact_fraction > 0.0);
    assert!(s.stats.x_max >= s.poincare.iter().map(|q| q.w_tip).fold(f64::MIN, f64::max));
    assert!(s.stats.v_t_min < 0.0, "the tip indents the sample");
}

#[test]
fn clustering_merges_one_attractor_and_separates_two() {
    let spec = |omega: f64| AttractorSpec {
        params: Params {
            omega,
            ..Params::default()
        },
        samples: 24,
        seed: 7,
        cluster_tol: 1e-5,
        steady: SteadyOptions::default(),
        integrator: IntegratorOptions::default(),
    };
    // Ω = 2.8: every start reaches the same period-2 orbit, entered at either phase
    let r = find_attractors(&spec(2.8), &Progress::new()).unwrap();
    assert_eq!(
        r.attractors.len(),
        1,
        "{:?}",
        r.attractors
            .iter()
            .map(|a| a.steady.motion.clone())
            .collect::<Vec<_>>()
    );
    assert_eq!(r.attractors[0].count, 24);
    // Ω = 1.8: two coexisting period-2 orbits with different contact fractions
    let r = find_attractors(&spec(1.8), &Progress::new()).unwrap();
    assert_eq!(r.attractors.len(), 2);
    let (a, b) = (&r.attractors[0].steady, &r.attractors[1].steady);
    assert!(!same_attractor(a, b, 1e-5) && !same_attractor(b, a, 1e-5));
    assert!((a.stats.contact_fraction - b.stats.contact_fraction).abs() > 0.01);
    assert!((r.attractors.iter().map(|x| x.basin_fraction).sum::<f64>() - 1.0).abs() < 1e-12);
}

#[test]
fn sweep_streams_every_point_once_and_resume_skips_done_points() {
    let spec = SweepSpec {
        base: Params::default(),
        param: SweepParam::Alpha2,
        values: SweepSpec::linspace(0.05, 0.12, 5).unwrap(),
        continuation: true,
        starts: 1,
        seed: 3,
        steady: SteadyOptions {
            max_periods: Some(400),
            ..SteadyOptions::default()
        },
        integrator: IntegratorOptions::default(),
    };
    spec.validate().unwrap();
    let seen = Mutex::new(Vec::new());
    run_sweep(&spec, &Resume::default(), &|p| {
        seen.lock()
            .unwrap()
            .push((p.index, p.branch, p.result.is_ok()))
    });
    let mut all = seen.into_inner().unwrap();
    all.sort();
    assert_eq!(all.len(), 15);
    all.dedup();
    assert_eq!(all.len(), 15, "each (value, branch) once");
    assert!(all.iter().all(|x| x.2));
    let mut resume = Resume::default();
    for i in 0..3 {
        resume.done.insert((i, Branch::Forward));
    }
    let again = Mutex::new(Vec::new());
    run_sweep(&spec, &resume, &|p| {
        again.lock().unwrap().push((p.index, p.branch))
    });
    let again = again.into_inner().unwrap();
    assert_eq!(again.len(), 12);
    assert!(!again.iter().any(|(i, b)| *b == Branch::Forward && *i < 3));
    // an invalid swept value is caught before running
    let bad = SweepSpec {
        values: vec![0.1, -0.2],
        ..spec
    };
    assert!(bad.validate().is_err());
}

/// The census polishes every periodic attractor by shooting: each reported Poincaré point is a
/// fixed point of the period-n map to round-off (the transient's last iterate is only within the
/// detection tolerance 1e-8), and the Floquet multipliers and stability are reported.
#[test]
fn attractor_census_reports_polished_orbits_with_multipliers() {
    let p = Params {
        omega: 2.8,
        ..Params::default()
    };
    let spec = AttractorSpec {
        params: p,
        samples: 3,
        seed: 7,
        cluster_tol: 1e-5,
        steady: SteadyOptions::default(),
        integrator: IntegratorOptions::default(),
    };
    let r = find_attractors(&spec, &Progress::new()).unwrap();
    let m = CantileverModel::new(&p).unwrap();
    let mut it = build(&m, IntegratorOptions::default(), 0.0, &m.rest()).unwrap();
    let mut checked = 0;
    for a in &r.attractors {
        let Some(n) = a.steady.period() else { continue };
        let orbit = a.orbit.as_ref().expect("periodic attractors are polished");
        assert_eq!(orbit.multipliers.len(), 6);
        assert_eq!(
            orbit.stable,
            orbit.multipliers.iter().all(|mu| mu.norm() < 1.0)
        );
        assert!(
            orbit.stable,
            "an attractor reached from random starts is stable"
        );
        for pt in &a.steady.poincare {
            let back = afmdyn::maps::StroboscopicMap::new(it.as_mut(), n)
                .apply(&pt.state)
                .unwrap()
                .state;
            let res = (&back - &pt.state).amax();
            assert!(res < 1e-11, "section point off its orbit by {res:e}");
            assert!((pt.v_t - m.v_t(0.0, &pt.state)).abs() < 1e-12);
        }
        checked += 1;
    }
    assert!(checked >= 1);
}

/// The census runs its starts in parallel; its result must be the census one by one: each
/// attractor's count, its first start, its period and its (unpolished) statistics are those of
/// clustering the steady states of `steady_state` run on each start alone, in start order.
#[test]
fn the_parallel_census_equals_the_census_one_by_one() {
    use afmdyn::analysis::bifurcation::random_state;
    use afmdyn::analysis::steady::steady_state;
    let p = Params {
        omega: 1.8,
        ..Params::default()
    };
    let spec = AttractorSpec {
        params: p,
        samples: 70,
        seed: 3,
        cluster_tol: 1e-5,
        steady: SteadyOptions::default(),
        integrator: IntegratorOptions::default(),
    };
    let report = find_attractors(&spec, &Progress::new()).unwrap();
    let m = CantileverModel::new(&p).unwrap();
    // one by one: (first start, steady state, count) per attractor in order of discovery
    let mut alone: Vec<(
        nalgebra::DVector<f64>,
        afmdyn::analysis::steady::SteadyState,
        usize,
    )> = Vec::new();
    for i in 0..spec.samples {
        let z0 = random_state(&m, spec.seed, i as u64);
        let mut it = build(&m, spec.integrator.clone(), 0.0, &z0).unwrap();
        let s = steady_state(it.as_mut(), &spec.steady).unwrap();
        match alone
            .iter_mut()
            .find(|(_, t, _)| same_attractor(t, &s, spec.cluster_tol))
        {
            Some(a) => a.2 += 1,
            None => alone.push((z0, s, 1)),
        }
    }
    assert!(alone.len() >= 2, "two attractors coexist at Ω = 1.8");
    assert_eq!(report.attractors.len(), alone.len());
    assert!(report.failures.is_empty());
    for (z0, s, count) in &alone {
        let a = report
            .attractors
            .iter()
            .find(|a| &a.initial == z0)
            .expect("the same first start");
        assert_eq!(a.count, *count);
        assert_eq!(a.steady.motion, s.motion);
        assert_eq!(a.steady.transient_periods, s.transient_periods);
        assert_eq!(a.steady.stats, s.stats);
    }
}

//! A real lever at its defaults (issue 42): the RTESPA-300 (Q = 500) over polystyrene,
//! `examples/probe-rtespa300-polystyrene.toml`, where an attractive-regime and a repulsive-regime
//! period-1 orbit coexist at z_c = 14.3 nm and a transient takes ~3 000 drive periods.

use afmdyn::analysis::attractors::{find_attractors, same_attractor, AttractorSpec};
use afmdyn::analysis::progress::Progress;
use afmdyn::analysis::steady::{
    decay_periods, default_transient_cap, steady_state, SteadyOptions, MIN_TRANSIENT_PERIODS,
    TRANSIENT_DECAY_TIMES,
};
use afmdyn::integrate::{build, IntegratorOptions};
use afmdyn::probe::Probe;
use afmdyn::request::{LyapunovRequest, ModelSpec};
use afmdyn::{CantileverModel, Params, SimError};

const PROBE: &str = include_str!("../../../examples/probe-rtespa300-polystyrene.toml");

fn lever(z_c: f64) -> Params {
    let probe = Probe::parse(PROBE, "rtespa").unwrap();
    ModelSpec {
        z_c: Some(z_c),
        ..ModelSpec::default()
    }
    .resolve(Params::default(), Some(&probe))
    .unwrap()
}

/// The derived transient cap is six decay times of the slowest free mode: for the point mass
/// (a damped oscillator ẍ + ẋ/Q + x = …, eigenvalues −1/(2Q) ± i√(1 − 1/(4Q²)) in units of
/// ω0) driven at Ω, ln(1/tol) / (T/(2Q)) = ln(1/tol) Q Ω/π periods — closed form, 17 591 at
/// Q = 500, Ω = 1, tol = 1e-8; the paper's beam keeps the floor of 1 500; a user's
/// `max_periods` wins.
#[test]
fn the_default_transient_cap_follows_the_quality_factor() {
    let p = lever(14.3e-9);
    let model = CantileverModel::new(&p).unwrap();
    let q = 500.0;
    let closed = (1e8f64).ln() * q * p.omega / std::f64::consts::PI;
    let decay = decay_periods(&model, 1e-8).unwrap();
    assert!(
        (decay - closed).abs() <= 1e-6 * closed,
        "{decay} vs {closed}"
    );
    let cap = default_transient_cap(&model, 1e-8);
    assert_eq!(cap, (TRANSIENT_DECAY_TIMES * decay).ceil() as usize);
    assert!((17_500..17_700).contains(&cap), "{cap}");
    let opts = SteadyOptions::default();
    assert_eq!(opts.cap(&model), cap);
    assert!(opts.newton_on(&model));
    let user = SteadyOptions {
        max_periods: Some(300),
        ..opts
    };
    assert_eq!(user.cap(&model), 300);
    // the paper's beam (Q ≈ 42 at Ω = 2.6): the floor, and no Newton from the transient; at
    // Ω = 5 its transient lasts as long in τ, more drive periods: a larger cap, still no Newton
    let paper = CantileverModel::new(&Params::default()).unwrap();
    assert_eq!(opts.cap(&paper), MIN_TRANSIENT_PERIODS);
    assert!(!opts.newton_on(&paper));
    let fast = CantileverModel::new(&Params {
        omega: 5.0,
        ..Params::default()
    })
    .unwrap();
    let ratio = decay_periods(&fast, 1e-8).unwrap() / decay_periods(&paper, 1e-8).unwrap();
    assert!((ratio - 5.0 / 2.6).abs() < 1e-9, "{ratio}");
    assert!(opts.cap(&fast) > MIN_TRANSIENT_PERIODS && !opts.newton_on(&fast));
}

/// Before the cap followed Q, `attractors --samples 16` on this probe reported 8 nonperiodic
/// attractors and no warning. At its defaults the census finds exactly the two period-1
/// orbits, with the basin fractions of the same starts run to a plain 20 000-period transient
/// (returns repeating to 1e-8, no Newton): within 0.05 (here: equal).
#[test]
fn the_census_of_a_high_q_lever_finds_its_two_orbits_at_defaults() {
    let spec = AttractorSpec {
        params: lever(14.3e-9),
        samples: 24,
        seed: 1,
        cluster_tol: 1e-5,
        steady: SteadyOptions::default(),
        integrator: IntegratorOptions::default(),
    };
    let fast = find_attractors(&spec, &Progress::new()).unwrap();
    let slow = find_attractors(
        &AttractorSpec {
            steady: SteadyOptions {
                max_periods: Some(20_000),
                newton: false,
                ..SteadyOptions::default()
            },
            ..spec.clone()
        },
        &Progress::new(),
    )
    .unwrap();
    for r in [&fast, &slow] {
        let periods: Vec<_> = r.attractors.iter().map(|a| a.steady.period()).collect();
        assert_eq!(periods, [Some(1), Some(1)], "{periods:?}");
        assert!(r.unsettled.is_empty() && r.warnings().is_empty());
    }
    for a in &fast.attractors {
        let b = slow
            .attractors
            .iter()
            .find(|b| same_attractor(&a.steady, &b.steady, 1e-5))
            .expect("the same orbit");
        assert!(
            (a.basin_fraction - b.basin_fraction).abs() <= 0.05,
            "{} vs {}",
            a.basin_fraction,
            b.basin_fraction
        );
        assert!(a.orbit.as_ref().is_some_and(|o| o.stable));
    }
    // the two orbits are 0.2 apart (relative): the attractive and the repulsive regime
    let (x0, x1) = (
        fast.attractors[0].steady.stats.x_max,
        fast.attractors[1].steady.stats.x_max,
    );
    assert!((x0 - x1).abs() > 0.03, "{x0} {x1}");
}

/// A start whose transient is cut short is never reported as an attractor without saying so:
/// with a 300-period cap every start ends nonperiodic; those still contracting (λ₁ < −2 × its
/// error) are not attractors, the others carry λ₁ and a warning names them and the cap.
#[test]
fn unsettled_ends_are_not_attractors_without_a_warning() {
    let r = find_attractors(
        &AttractorSpec {
            params: lever(14.3e-9),
            samples: 8,
            seed: 1,
            cluster_tol: 1e-5,
            steady: SteadyOptions {
                max_periods: Some(300),
                newton: false,
                ..SteadyOptions::default()
            },
            integrator: IntegratorOptions::default(),
        },
        &Progress::new(),
    )
    .unwrap();
    let warnings = r.warnings();
    assert!(!warnings.is_empty());
    assert!(warnings.iter().all(|w| w.contains("300")), "{warnings:?}");
    for a in &r.unsettled {
        let (l, e) = a.lyapunov.unwrap();
        assert!(l < -2.0 * e);
    }
    for a in r.attractors.iter().filter(|a| a.steady.period().is_none()) {
        let (l, e) = a.lyapunov.expect("λ₁ of a nonperiodic end");
        assert!(l > 2.0 * e || warnings.iter().any(|w| w.contains("λ₁ ≈ 0")));
    }
    let ends: usize = r
        .unsettled
        .iter()
        .chain(&r.attractors)
        .map(|a| a.count)
        .sum();
    assert_eq!(ends, 8);
}

/// A start decided by Newton from the transient ends on the orbit: its Poincaré point is a
/// fixed point of the stroboscopic map to the shooting tolerance, and the start is decided in
/// fewer periods than the returns take to repeat to 1e-8.
#[test]
fn a_start_decided_by_newton_lies_on_its_orbit() {
    let p = lever(14.3e-9);
    let model = CantileverModel::new(&p).unwrap();
    let z0 = afmdyn::analysis::bifurcation::random_state(&model, 1, 0);
    let mut it = build(&model, IntegratorOptions::default(), 0.0, &z0).unwrap();
    let fast = steady_state(it.as_mut(), &SteadyOptions::default()).unwrap();
    let mut it = build(&model, IntegratorOptions::default(), 0.0, &z0).unwrap();
    let plain = steady_state(
        it.as_mut(),
        &SteadyOptions {
            newton: false,
            ..SteadyOptions::default()
        },
    )
    .unwrap();
    assert_eq!((fast.period(), plain.period()), (Some(1), Some(1)));
    assert!(fast.transient_periods < plain.transient_periods);
    let z = fast.end_state().clone();
    let mut it = build(&model, IntegratorOptions::default(), 0.0, &z).unwrap();
    afmdyn::integrate::advance(it.as_mut(), p.period()).unwrap();
    let r = (it.state() - &z).norm() / (1.0 + z.norm());
    assert!(r < 1e-9, "P(z) − z: {r:e}");
    // the plain search ends within tol/(1 − |μ₁|) of the same orbit
    assert!((plain.end_state() - &z).norm() / (1.0 + z.norm()) < 1e-5);
}

/// Tolerances out of their range are refused, naming the option: `tol` = 1e300 would take a
/// chaotic motion for period 1, 0 or NaN never matches.
#[test]
fn the_return_tolerance_has_a_range() {
    let model = CantileverModel::new(&Params::default()).unwrap();
    for tol in [1e300, 1e-2, 0.0, -1.0, f64::NAN, 1e-16] {
        let mut it = build(
            &model,
            IntegratorOptions::default(),
            0.0,
            &nalgebra::DVector::zeros(6),
        )
        .unwrap();
        let e = steady_state(
            it.as_mut(),
            &SteadyOptions {
                tol,
                ..SteadyOptions::default()
            },
        )
        .unwrap_err();
        assert!(
            matches!(&e, SimError::OutOfRange { name, .. } if *name == "tol"),
            "{tol}: {e}"
        );
    }
}

/// `lyapunov` discards the derived transient by default: the request without `transient`
/// equals the one given the model's derived cap.
#[test]
fn the_lyapunov_transient_is_derived_by_default() {
    let p = Params::default();
    let r = LyapunovRequest {
        periods: 50,
        blocks: 5,
        ..LyapunovRequest::default()
    };
    assert_eq!(r.transient, None);
    let progress = afmdyn::analysis::progress::Progress::new();
    let a = r.run(&p, &progress).unwrap();
    let model = CantileverModel::new(&p).unwrap();
    let b = LyapunovRequest {
        transient: Some(default_transient_cap(&model, 1e-8)),
        ..r.clone()
    }
    .run(&p, &progress)
    .unwrap();
    assert_eq!(a.exponents, b.exponents);
    let c = LyapunovRequest {
        transient: Some(500),
        ..r
    }
    .run(&p, &progress)
    .unwrap();
    assert_ne!(a.exponents, c.exponents);
}

/// A start on the saddle between the two orbits (|μ₁| = 1.0035) lingers there for thousands
/// of periods, its returns repeating to 1e-8: they are a passage, not the steady state. The
/// search goes on until the motion leaves for one of the two stable orbits (before, a basin
/// map of this probe labelled 0.3 % of its cells with the saddle).
#[test]
fn a_passage_near_the_saddle_is_not_a_steady_state() {
    use afmdyn::analysis::shooting::{shoot, ShootingOptions};
    use afmdyn::maps::StroboscopicMap;
    let p = lever(14.3e-9);
    let model = CantileverModel::new(&p).unwrap();
    let newton = |z| {
        let mut it = build(&model, IntegratorOptions::default(), 0.0, &model.rest()).unwrap();
        let map = &mut StroboscopicMap::new(it.as_mut(), 1);
        shoot(map, z, &ShootingOptions::default()).unwrap()
    };
    // the saddle, from a state near it (a basin map's third "attractor")
    let near = nalgebra::DVector::from_vec(vec![-0.2178, 0.9493]);
    let saddle = newton(&near);
    assert!(!saddle.stable && saddle.multipliers[0].norm() > 1.0);
    let z0 = &saddle.state + nalgebra::DVector::from_vec(vec![1e-9, 0.0]);
    let mut it = build(&model, IntegratorOptions::default(), 0.0, &z0).unwrap();
    let s = steady_state(it.as_mut(), &SteadyOptions::default()).unwrap();
    assert_eq!(s.period(), Some(1));
    let end = s.end_state().clone();
    let orbit = newton(&end);
    assert!(orbit.stable, "ended on {:?}", orbit.multipliers[0]);
    assert!((&orbit.state - &saddle.state).norm() > 0.05);
}

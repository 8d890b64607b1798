//! Issue 9: budgets checked before any work (grid memory, adaptive steps, sweep size, initial
//! state), and a fuzz test over the whole allowed parameter box: no panic, no hang, a finite
//! state or a typed error.

use afmdyn::analysis::bifurcation::{SweepSpec, MAX_SWEEP_POINTS};
use afmdyn::analysis::steady::SteadyOptions;
use afmdyn::integrate::{build, IntegratorKind, IntegratorOptions};
use afmdyn::params::{ALPHA1_MAX, ALPHA4_MAX, DAMPING_MAX, DISPLACEMENT_MAX, OMEGA_MAX, OMEGA_MIN};
use afmdyn::{CantileverModel, Params, SimError, SweepParam};
use nalgebra::DVector;
use proptest::prelude::*;
use std::time::{Duration, Instant};

#[test]
fn exact_grid_beyond_the_memory_budget_is_refused_before_allocating() {
    // Ω = 1e-3 with 20 modes needs ~6e6 grid steps per period (1.9 GB): refused, at once
    let p = Params {
        modes: 20,
        omega: 1e-3,
        ..Params::default()
    };
    let model = CantileverModel::new(&p).unwrap();
    let t = Instant::now();
    let e = build(&model, IntegratorOptions::default(), 0.0, &model.rest())
        .err()
        .expect("over budget");
    assert!(matches!(e, SimError::Budget { .. }), "{e}");
    assert!(e.to_string().contains("128 MiB"), "{e}");
    assert!(t.elapsed() < Duration::from_secs(5));
    // a samples-per-period request that would blow the grid up is refused too
    let model = CantileverModel::new(&Params::default()).unwrap();
    let opts = IntegratorOptions {
        steps_per_period: 10_000_000,
        ..IntegratorOptions::default()
    };
    assert!(matches!(
        build(&model, opts, 0.0, &model.rest()),
        Err(SimError::Budget { .. })
    ));
}

#[test]
fn adaptive_oracle_beyond_its_step_budget_is_refused() {
    let p = Params {
        omega: 1e-3,
        ..Params::default()
    };
    let model = CantileverModel::new(&p).unwrap();
    let opts = IntegratorOptions {
        kind: IntegratorKind::Adaptive,
        ..IntegratorOptions::default()
    };
    assert!(matches!(
        build(&model, opts, 0.0, &model.rest()),
        Err(SimError::Budget { .. })
    ));
}

#[test]
fn initial_state_at_the_divergence_threshold_is_refused() {
    let model = CantileverModel::new(&Params::default()).unwrap();
    for big in [1e12, 1e300] {
        let z = DVector::from_vec(vec![big, 0.0, 0.0, 0.0, 0.0, 0.0]);
        let e = build(&model, IntegratorOptions::default(), 0.0, &z)
            .err()
            .expect("refused");
        assert!(e.to_string().contains("initial state"), "{e}");
        assert!(matches!(e, SimError::OutOfRange { .. }));
    }
    let z = DVector::from_vec(vec![1e11, 0.0, 0.0, 0.0, 0.0, 0.0]);
    assert!(build(&model, IntegratorOptions::default(), 0.0, &z).is_ok());
}

#[test]
fn sweep_size_is_bounded_before_allocating() {
    // `--steps 18446744073709551615` overflowed a Vec's capacity; `--steps 1e8` took 1.5 GB
    for steps in [usize::MAX, 100_000_000, MAX_SWEEP_POINTS + 1] {
        assert!(matches!(
            SweepSpec::linspace(1.0, 5.0, steps),
            Err(SimError::OutOfRange { name: "steps", .. })
        ));
    }
    let values = SweepSpec::linspace(1.0, 5.0, 1000).unwrap();
    let spec = |starts: u32| SweepSpec {
        base: Params::default(),
        param: SweepParam::Omega,
        values: values.clone(),
        continuation: true,
        starts,
        seed: 1,
        steady: SteadyOptions::default(),
        integrator: IntegratorOptions::default(),
    };
    assert!(spec(10).validate().is_ok());
    let e = spec(u32::MAX).validate().unwrap_err();
    assert!(e.to_string().contains("sweep points"), "{e}");
}

/// A value in [0, max] spread over all decades (with 0 and the limit itself).
fn magnitude(max: f64) -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(0.0),
        Just(max),
        (-8.0..max.log10()).prop_map(|e: f64| 10f64.powf(e)),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 32,
        failure_persistence: super::common::regressions_beside_the_source(),
        ..ProptestConfig::default()
    })]

    /// Anywhere in the allowed box (and with states up to 1e6): building either fails with a
    /// typed error or yields an integrator whose steps finish quickly with a finite state or a
    /// typed error (diverged, chattering). Never a panic or a hang.
    #[test]
    fn allowed_parameter_box_never_panics_or_hangs(
        modes in prop_oneof![1usize..=4, Just(20usize), 5usize..=20],
        a1 in magnitude(ALPHA1_MAX),
        a2 in magnitude(DISPLACEMENT_MAX),
        a3 in magnitude(DAMPING_MAX),
        a4 in magnitude(ALPHA4_MAX),
        a5 in magnitude(DISPLACEMENT_MAX),
        a5_negative in any::<bool>(),
        a6 in magnitude(DAMPING_MAX),
        log_omega in OMEGA_MIN.log10()..=OMEGA_MAX.log10(),
        state in proptest::collection::vec(-1e6..1e6f64, 40),
        kind in prop_oneof![Just(IntegratorKind::Exact), Just(IntegratorKind::Rk4)],
    ) {
        // `..Params::default()` keeps this compiling when Params gains fields (a contact law)
        #[allow(clippy::needless_update)]
        let p = Params {
            modes,
            alpha1: a1,
            alpha2: a2,
            alpha3: a3,
            alpha4: a4,
            alpha5: if a5_negative { -a5 } else { a5 },
            alpha6: a6,
            omega: 10f64.powf(log_omega).clamp(OMEGA_MIN, OMEGA_MAX),
            ..Params::default()
        };
        prop_assert!(p.validate().is_ok());
        let t = Instant::now();
        let model = CantileverModel::new(&p).unwrap();
        let z = DVector::from_column_slice(&state[..2 * modes]);
        let opts = IntegratorOptions { kind, steps_per_period: 200, ..IntegratorOptions::default() };
        match build(&model, opts, 0.0, &z) {
            Err(e) => prop_assert!(matches!(e, SimError::Budget { .. }), "{e}"),
            Ok(mut integ) => {
                // the exact propagator: every step finite (at most 2000 of them). Fixed-step RK4
                // is unstable for h·ω_max > 2.8 and may overflow inside a period (reported as
                // diverged only at the period's end): no panic, no hang, but no finiteness either
                let end = 2.0 * model.period();
                for _ in 0..2000 {
                    match integ.step(end) {
                        Ok(_) => prop_assert!(
                            kind != IntegratorKind::Exact
                                || integ.state().iter().all(|v| v.is_finite())
                        ),
                        Err(e) => {
                            prop_assert!(
                                matches!(e, SimError::Diverged { .. } | SimError::Chattering { .. }),
                                "{e}"
                            );
                            break;
                        }
                    }
                    if integ.tau() >= end {
                        break;
                    }
                }
            }
        }
        prop_assert!(t.elapsed() < Duration::from_secs(20), "took {:?} for {p:?}", t.elapsed());
    }
}

/// Issue 59 (Deliver 2): every request declares its cost (peak memory, work in mode-periods)
/// before it runs, and `run` refuses it beyond the budgets of `request::limits`.
mod costs {
    use afmdyn::analysis::progress::Progress;
    use afmdyn::request::limits::{Cost, MAX_REQUEST_BYTES, MAX_REQUEST_WORK};
    use afmdyn::request::Request;
    use afmdyn::request::{
        run, Analysis, ApproachRequest, AttractorsRequest, BasinsRequest, ContinuationRequest,
        ConvergeRequest, FmRequest, GlobalContinuationRequest, LyapunovRequest, ModesRequest,
        ObserveRequest, OrbitRequest, ReconstructRequest, Resolved, ResonanceRequest,
        SteadyRequest,
    };
    use afmdyn::{Params, SimError};

    fn model() -> Resolved {
        Resolved::plain(Params::default())
    }

    fn within(what: &str, c: Cost) {
        assert!(
            c.bytes <= MAX_REQUEST_BYTES && c.work <= MAX_REQUEST_WORK,
            "{what}: {c:?} should be within the budgets"
        );
        assert!(c.bytes > 0.0 && c.work >= 0.0, "{what}: {c:?}");
    }

    /// `a` is refused by `run` naming the request and the budget, before any work (nothing
    /// counted in its progress).
    fn refused<A: Analysis>(a: &A, budget: &str) {
        refused_on(a, &model(), budget)
    }

    /// [`refused`] on `m`.
    fn refused_on<A: Analysis>(a: &A, m: &Resolved, budget: &str) {
        let progress = Progress::new();
        let e = run(a, m, &progress)
            .err()
            .unwrap_or_else(|| panic!("{}: {:?} should be over the budgets", a.name(), a.cost(m)));
        assert!(matches!(e, SimError::Budget { .. }), "{}: {e}", a.name());
        let text = e.to_string();
        assert!(text.starts_with(a.name()), "{text}");
        assert!(text.contains(budget), "{text}");
        // the fields that drive the cost, and the size that would fit (issue 77 item 1)
        assert!(text.contains(A::COST_ADVICE), "{text}");
        let cost = a.cost(m).expect("cost");
        // the memory is checked first
        let over = match cost.bytes / afmdyn::request::limits::MAX_REQUEST_BYTES {
            m if m > 1.0 => m,
            _ => cost.work / afmdyn::request::limits::MAX_REQUEST_WORK,
        };
        let fits = format!("{:.0} % of this size fits", 100.0 / over);
        assert!(
            over < 10.0 && text.contains(&fits) || over >= 10.0,
            "{text}: {fits}"
        );
        assert_eq!(progress.done(), 0, "{}: refused before any work", a.name());
    }

    fn steady(max_periods: usize) -> SteadyRequest {
        SteadyRequest {
            max_periods: Some(max_periods),
            ..SteadyRequest::default()
        }
    }

    #[test]
    fn default_requests_cost_within_the_budgets() {
        let m = model();
        within("modes", ModesRequest::default().cost(&m).unwrap());
        within("orbit", OrbitRequest::default().cost(&m).unwrap());
        within(
            "continuation",
            ContinuationRequest::default().cost(&m).unwrap(),
        );
        within("lyapunov", LyapunovRequest::default().cost(&m).unwrap());
        within("attractors", AttractorsRequest::default().cost(&m).unwrap());
        within("observe", ObserveRequest::default().cost(&m).unwrap());
        within("converge", ConvergeRequest::default().cost(&m).unwrap());
        within("approach", ApproachRequest::default().cost(&m).unwrap());
        within("resonance", ResonanceRequest::default().cost(&m).unwrap());
        within("basins", BasinsRequest::default().cost(&m).unwrap());
        within(
            "attractors --sweep",
            GlobalContinuationRequest::default().cost(&m).unwrap(),
        );
        within("fm", FmRequest::default().cost(&m).unwrap());
        let curve = ReconstructRequest {
            distance: Some((0..1000).map(|i| 1e-10 * (1.0 + i as f64)).collect()),
            z_c: None,
            frequency_shift: (0..1000).map(|i| -100.0 / (1.0 + i as f64)).collect(),
            spring_constant: 40.0,
            resonance_frequency: 300e3,
            amplitude: 1e-9,
            law_force: None,
            inversion: Default::default(),
        };
        within("reconstruct", curve.cost(&m).unwrap());
        let exact = ReconstructRequest {
            inversion: afmdyn::request::reconstruct::FmInversion::Exact,
            ..curve
        };
        within("reconstruct --inversion exact", exact.cost(&m).unwrap());
    }

    /// The requests whose options bound their cost one by one stay within the budgets at the
    /// options' limits: the orbit, its continuation and the observables at the largest period
    /// and transient, an FM curve of the most points.
    #[test]
    fn requests_bounded_option_by_option_stay_within_the_budgets_at_their_limits() {
        let m = model();
        let start = afmdyn::request::StartRequest {
            initial: None,
            steady: SteadyRequest {
                max_period: 64,
                ..steady(10_000_000)
            },
        };
        let orbit = OrbitRequest {
            period: Some(64),
            start: start.clone(),
        };
        within("orbit", orbit.cost(&m).unwrap());
        let observe = ObserveRequest {
            periods: 1_000_000,
            harmonics: 10_000,
            start,
        };
        within("observe", observe.cost(&m).unwrap());
        let lyapunov = LyapunovRequest {
            transient: Some(10_000_000),
            periods: 90_000_000,
            blocks: 1000,
            ..LyapunovRequest::default()
        };
        within("lyapunov", lyapunov.cost(&m).unwrap());
    }

    #[test]
    fn requests_just_over_their_budget_are_refused_before_any_work() {
        // work = starts × transient cap × 3 modes: 50 000 × 666 667 × 3 just over 1e11, and
        // one period less just within
        let census = |max_periods| AttractorsRequest {
            samples: 50_000,
            steady: steady(max_periods),
            ..AttractorsRequest::default()
        };
        within("attractors", census(666_666).cost(&model()).unwrap());
        refused(&census(666_667), "1e11 mode-periods");
        let sweep = |max_periods| GlobalContinuationRequest {
            steps: 10,
            samples: 5_000,
            steady: steady(max_periods),
            ..GlobalContinuationRequest::default()
        };
        within("attractors --sweep", sweep(666_666).cost(&model()).unwrap());
        refused(&sweep(666_667), "1e11 mode-periods");
        let basins = |max_periods| BasinsRequest {
            x_steps: 500,
            y_steps: 100,
            steady: steady(max_periods),
            ..BasinsRequest::default()
        };
        within("basins", basins(666_666).cost(&model()).unwrap());
        refused(&basins(666_667), "1e11 mode-periods");
        // a curve's traces: 1000 points × 16 periods × 24 bytes × samples per period, 3.5
        // times while they are recorded and laid out: 700 samples take 0.94 GB, 1000 1.34 GB
        // (and 0.38 GB by the traces' own budget of 1 GiB, which lets them through)
        let traced = |samples| afmdyn::request::CurveRequest {
            points: Some(1000),
            branches: false,
            traces: Some(samples),
            ..afmdyn::request::CurveRequest::default()
        };
        let approach = ApproachRequest {
            curve: traced(700),
            ..ApproachRequest::default()
        };
        within("approach", approach.cost(&model()).unwrap());
        let approach = ApproachRequest {
            curve: traced(1000),
            ..ApproachRequest::default()
        };
        refused(&approach, "1.1 GiB");
        let resonance = ResonanceRequest {
            curve: traced(2000),
            ..ResonanceRequest::default()
        };
        refused(&resonance, "1.1 GiB");
        // memory: converge keeps every run's samples (24 bytes each) and records the last
        // run's trajectory whole (some 250 bytes a sample at N = 3): 3 × 2·10^6 samples take
        // about 0.6 GB, 3 × 4·10^6 about 1.3 GB
        let converge = |periods| ConvergeRequest {
            max_modes: 3,
            periods,
            samples_per_period: 1_000,
            ..ConvergeRequest::default()
        };
        within("converge", converge(2_000).cost(&model()).unwrap());
        refused(&converge(4_000), "1.1 GiB");
    }
}

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
    #![proptest_config(ProptestConfig { cases: 32, .. ProptestConfig::default() })]

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

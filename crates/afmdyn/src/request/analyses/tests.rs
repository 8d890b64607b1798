//! Tests of the analysis requests: defaults, limits, budgets, initial states.

use super::*;

fn name(e: SimError) -> &'static str {
    match e {
        SimError::OutOfRange { name, .. } => name,
        SimError::StateLength { .. } => "length",
        SimError::Budget { .. } => "budget",
        other => panic!("unexpected {other:?}"),
    }
}

/// Every default request is valid (the defaults of `--help` and of the Python functions
/// must run), and each limit is refused naming its parameter.
#[test]
fn defaults_pass_and_each_limit_names_its_parameter() {
    let p = Params::default();
    assert!(SteadyRequest::default().options().is_ok());
    assert!(OrbitRequest::default().validate().is_ok());
    assert!(ContinuationRequest::default().validate(&p).is_ok());
    assert!(LyapunovRequest::default().validate().is_ok());
    assert!(AttractorsRequest::default().spec(&p).is_ok());
    assert!(ObserveRequest::default().validate().is_ok());
    assert!(ConvergeRequest::default().validate().is_ok());
    assert!(BifurcationRequest::default().spec(&p).is_ok());
    let span = SimulateRequest::default()
        .validate(&p, SeriesStore::Memory, 13, 8.0)
        .unwrap();
    // 50 periods of 200 samples, ends included
    assert_eq!(span.rows, 10_001.0);
    let steady = |tol, max_periods, max_period| SteadyRequest {
        tol,
        max_periods: Some(max_periods),
        max_period,
    };
    assert_eq!(name(steady(0.0, 10, 8).options().unwrap_err()), "tol");
    assert_eq!(
        name(steady(1e-8, 0, 8).options().unwrap_err()),
        "max_periods"
    );
    assert_eq!(
        name(steady(1e-8, 10, 65).options().unwrap_err()),
        "max_period"
    );
    let orbit = OrbitRequest {
        period: Some(65),
        ..OrbitRequest::default()
    };
    assert_eq!(name(orbit.validate().unwrap_err()), "period");
    let att = AttractorsRequest {
        samples: MAX_ATTRACTOR_SAMPLES + 1,
        ..AttractorsRequest::default()
    };
    assert_eq!(name(att.spec(&p).unwrap_err()), "samples");
    let bif = BifurcationRequest {
        threads: Some(MAX_THREADS + 1),
        ..BifurcationRequest::default()
    };
    assert_eq!(name(bif.spec(&p).unwrap_err()), "threads");
    let ly = LyapunovRequest {
        transient: Some(50_000_001),
        periods: 50_000_000,
        ..LyapunovRequest::default()
    };
    assert_eq!(name(ly.validate().unwrap_err()), "periods");
}

/// A run beyond 1e8 periods is refused; the series budget depends on where it is kept
/// (1e6 periods × 200 samples × 13 columns × 8 bytes = 20.8 GB: over both budgets; 1e5
/// periods: 2.1 GB, under the memory budget), and nothing kept has no budget.
#[test]
fn simulate_spans_and_budgets() {
    let p = Params::default();
    let run = |periods: f64| SimulateRequest {
        periods: Some(periods),
        ..SimulateRequest::default()
    };
    assert_eq!(
        name(
            run(2e8)
                .validate(&p, SeriesStore::Nothing, 13, 8.0)
                .unwrap_err()
        ),
        "periods"
    );
    for store in [SeriesStore::Memory, SeriesStore::Files] {
        assert_eq!(
            name(run(1e6).validate(&p, store, 13, 8.0).unwrap_err()),
            "budget"
        );
    }
    assert!(run(1e6).validate(&p, SeriesStore::Nothing, 13, 8.0).is_ok());
    assert!(run(1e5).validate(&p, SeriesStore::Memory, 13, 8.0).is_ok());
    let both = SimulateRequest {
        periods: Some(2.0),
        tau_end: Some(3.0),
        ..SimulateRequest::default()
    };
    assert_eq!(
        name(
            both.validate(&p, SeriesStore::Nothing, 13, 8.0)
                .unwrap_err()
        ),
        "periods"
    );
}

/// The initial state: 2N values, finite, below 1e11; rest when none is given.
#[test]
fn initial_states() {
    let model = CantileverModel::new(&Params::default()).unwrap();
    assert_eq!(initial_state(&model, None).unwrap(), model.rest());
    let z = [0.1, 0.0, 0.0, 0.0, 0.2, 0.0];
    assert_eq!(initial_state(&model, Some(&z)).unwrap().as_slice(), &z);
    assert_eq!(
        name(initial_state(&model, Some(&z[..4])).unwrap_err()),
        "length"
    );
    for bad in [f64::NAN, f64::INFINITY, 2e11] {
        let mut w = z;
        w[3] = bad;
        let e = initial_state(&model, Some(&w)).unwrap_err();
        assert!(
            e.to_string().contains("must be finite and below 1e11"),
            "{e}"
        );
    }
}

/// Issue 59: `simulate` (streamed to files) and `bifurcation` enter through the one door, so
/// a request beyond the budgets is refused by its cost before any work (nothing counted),
/// naming the request; the same requests within the budgets are admitted.
#[cfg(feature = "files")]
#[test]
fn simulate_and_bifurcation_beyond_the_budget_are_refused_before_any_work() {
    use crate::analysis::progress::Progress;
    use crate::request::run::{admit, run, Resolved};
    use crate::request::simulate_stream::SimulateStream;
    let model = Resolved::plain(Params::default());
    let refused = |e: SimError| match e {
        SimError::Budget { what, .. } => what,
        other => panic!("unexpected {other:?}"),
    };
    // a sweep of 1e6 points with a transient cap of 1e5 periods: 3e11 mode-periods
    let sweep = BifurcationRequest {
        values: Some(vec![2.6, 2.8]),
        starts: 499_998,
        steady: SteadyRequest {
            max_periods: Some(100_000),
            ..SteadyRequest::default()
        },
        ..BifurcationRequest::default()
    };
    let progress = Progress::new();
    assert_eq!(
        refused(run(&sweep, &model, &progress).unwrap_err()),
        "bifurcation"
    );
    assert_eq!((progress.done(), progress.total()), (0, None));
    let small = BifurcationRequest {
        steps: 7,
        ..BifurcationRequest::default()
    };
    assert!(admit(&small, &model).is_ok());
    // a run held in one chunk of 1e6 periods of 100 samples: 1e8 samples in memory at once
    // (within the files' budget on disk, 9.6 GB)
    let long = SimulateStream {
        request: SimulateRequest {
            periods: Some(1e6),
            samples_per_period: 100,
            ..SimulateRequest::default()
        },
        dir: Some(std::env::temp_dir().join("afmdyn-never-written")),
        figures: true,
        csv: false,
        chunk_periods: Some(1_000_000),
    };
    assert_eq!(
        refused(run(&long, &model, &progress).unwrap_err()),
        "simulate"
    );
    assert_eq!((progress.done(), progress.total()), (0, None));
    assert!(!long.dir.as_ref().unwrap().exists());
    // the same run in the default chunks is admitted (its series streamed to the files)
    let chunked = SimulateStream {
        chunk_periods: None,
        ..long
    };
    assert!(admit(&chunked, &model).is_ok());
}

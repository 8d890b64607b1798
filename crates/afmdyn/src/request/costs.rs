//! What a request costs before it runs ([`super::Request::cost`]): its peak memory and its
//! work, estimated for the worst case its options allow, and held by [`super::run()`] against
//! the budgets of [`super::limits`] ([`check_cost`]), so that a request too large is refused
//! naming its cost and the budget — before any allocation or integration — instead of
//! aborting on allocation or running for weeks.
//!
//! Work is counted in mode-periods: drive periods integrated × the model's modes N (a drive
//! period's cost grows about linearly with N at N ≥ 3: 2.3 µs at N = 3, 11 µs at N = 10, 59 µs at
//! N = 20 for the exact propagator, `docs/performance.md`). A steady-state search counts its
//! transient cap ([`crate::analysis::steady::SteadyOptions::cap`]), a Newton solve on an orbit of
//! period n its [`crate::analysis::shooting::ShootingOptions::max_iter`] iterations of n
//! periods of the state and its 2N-column variational system, `(2N + 1) n`. A request that
//! integrates nothing (`fit` of a force curve, `reconstruct`) counts its elementary operations
//! at [`OPERATION_WORK`] each.

use super::limits::{Cost, GIB, MAX_REQUEST_BYTES, MAX_REQUEST_WORK};
use crate::analysis::attractors::AttractorSpec;
use crate::analysis::basins::BasinSpec;
use crate::analysis::shooting::ShootingOptions;
use crate::analysis::steady::SteadyOptions;
use crate::analysis::stepped::SteppedSpec;
use crate::error::SimError;
use crate::model::CantileverModel;
use crate::params::Params;

/// Memory of a model and its propagators, held by every request, in bytes: 1 MiB (N ≤ 20:
/// a few dozen 2N × 2N matrices per contact region).
pub(crate) const MODEL_BYTES: f64 = 1024.0 * 1024.0;

/// Work of one elementary operation of a request that integrates nothing (a row of a force
/// curve's model with its Jacobian, a pair of a direct sum, a butterfly of an FFT), in
/// mode-periods: 0.1, about 80 ns at N = 3's 0.77 µs a mode-period, against the 8 ns (Hertz) and
/// 29 ns (SLS) a row-evaluation of `fit` and the 13 ns a pair of `reconstruct` measured
/// (`tests/door.rs` holds the time of each against it).
pub(crate) const OPERATION_WORK: f64 = 0.1;

/// Memory of a state (2N values and the law's internal ones), in bytes.
pub(crate) fn state_bytes(params: &Params) -> f64 {
    params.state_dim() as f64 * 8.0
}

/// The drive periods of a steady-state search on `params` (its transient cap: `max_periods`,
/// else the one derived from the model's slowest decay).
///
/// # Errors
/// [`SimError::Params`] when the model cannot be built.
pub(crate) fn steady_periods(steady: &SteadyOptions, params: &Params) -> Result<f64, SimError> {
    Ok(steady.cap(&CantileverModel::new(params)?) as f64)
}

/// The mode-periods of a Newton solve of an orbit of `period` drive periods on `params`
/// (`max_iter` iterations of the state and its variational system: see the module).
pub(crate) fn newton_work(params: &Params, period: usize, newton: &ShootingOptions) -> f64 {
    let columns = 2.0 * params.modes as f64 + 1.0;
    newton.max_iter as f64 * period as f64 * columns * params.modes as f64
}

/// Check `cost`, the cost of the request `what`, against [`MAX_REQUEST_BYTES`] and
/// [`MAX_REQUEST_WORK`].
///
/// # Errors
/// [`SimError::Budget`] naming the request, its cost and the budget.
pub(crate) fn check_cost(what: &'static str, cost: Cost) -> Result<(), SimError> {
    check_cost_advising(
        what,
        cost,
        "ask for fewer points, samples, cells or periods",
        "ask for fewer points, samples, cells or periods, or a shorter transient \
         (max_periods)",
    )
}

/// [`check_cost`] with the request's own advice, for memory and for work (a fit names its rows
/// and its profiles, not points or periods).
///
/// # Errors
/// [`SimError::Budget`] naming the request, its cost, the budget and the advice.
pub(crate) fn check_cost_advising(
    what: &'static str,
    cost: Cost,
    memory_hint: &'static str,
    work_hint: &'static str,
) -> Result<(), SimError> {
    // the size that would fit, for a cost that grows with the request's size
    let fits = |over: f64| {
        let percent = 100.0 / over;
        match percent {
            p if !p.is_finite() || p <= 0.0 => String::new(),
            p if p >= 10.0 => format!(" (about {p:.0} % of this size fits)"),
            p if p >= 1.0 => format!(" (about {p:.1} % of this size fits)"),
            p if p >= 0.01 => format!(" (about {p:.2} % of this size fits)"),
            p => format!(" (about {p:.1e} % of this size fits)"),
        }
    };
    // NaN (an estimate that overflowed) is refused too
    let over = |v: f64, most: f64, needed: String, budget: String, hint| {
        let needed = needed + &fits(v / most);
        let refused = SimError::Budget {
            what,
            needed,
            budget,
            hint,
        };
        if v <= most {
            Ok(())
        } else {
            Err(refused)
        }
    };
    let gib = format!("{:.1} GiB", MAX_REQUEST_BYTES / GIB);
    let memory = format!("a peak memory of {:.2} GiB", cost.bytes / GIB);
    over(cost.bytes, MAX_REQUEST_BYTES, memory, gib, memory_hint)?;
    let periods = format!(
        "{:.3e} mode-periods (drive periods integrated × modes)",
        cost.work
    );
    let most = format!("{MAX_REQUEST_WORK:.0e} mode-periods");
    over(cost.work, MAX_REQUEST_WORK, periods, most, work_hint)
}

/// The cost of `values` censuses of attractors ([`AttractorSpec`]: `attractors`, and one per
/// value of `attractors --sweep`): every random start searched to its transient cap; each
/// start's end state and Poincaré points (at most `max_period` states) kept.
///
/// # Errors
/// [`SimError::Params`] when the model cannot be built.
pub(crate) fn census_cost(spec: &AttractorSpec, values: usize) -> Result<Cost, SimError> {
    let p = &spec.params;
    let starts = values as f64 * spec.samples as f64;
    let per_start = (spec.steady.max_period as f64 + 2.0) * state_bytes(p) + 128.0;
    Ok(Cost {
        bytes: MODEL_BYTES + starts * per_start,
        work: starts * steady_periods(&spec.steady, p)? * p.modes as f64,
    })
}

/// The memory of a trajectory's sample as [`crate::trajectory::record`] holds it, for a state
/// of `params`, in bytes: the sample and its state's heap block, twice (a growing vector's old
/// and new blocks are both live while it is copied).
pub(crate) fn recorded_sample_bytes(params: &Params) -> f64 {
    2.0 * (std::mem::size_of::<crate::trajectory::Sample>() as f64 + state_bytes(params))
}

/// What the traces of a curve take at their peak for the bytes of their samples
/// ([`super::curves::trace_bytes`]): 3.5, measured 2.27 for the run (872 bytes per point and
/// sample per period at 2000 samples, 60 and 120 points, 1 and 2 threads, against 384 for 16
/// periods of 24 bytes: the vectors grow by doubling while a trace is recorded) and 2.95 with
/// the named door's outcome (its arrays beside the traces: 40 points at 500 samples, 60 at
/// 2000; `tests/door.rs`).
pub(crate) const TRACE_GROWTH: f64 = 3.5;

/// The work of the lock-in's thermal noise at one point of a stepped curve, in drive periods of
/// the model per mode (`stepped_cost`): its period of variational flows in 512 parts and the
/// products of its chain. Measured 2 ms a point against 0.125 ms a simulated period
/// (`approach --points 60 --no-branches` with and without `--temperature`, `simulate --periods
/// 2000`, examples/probe-beam-dmt.toml): 16 periods.
pub(crate) const NOISE_PERIODS: f64 = 16.0;

/// The cost of a stepped curve (`approach`, `resonance`): every point's steady state (one way,
/// and back with branches: each value twice), up to `max_branch_points` Newton solves of the
/// largest period per branch, the traces' worst case ([`super::curves::trace_bytes`] ×
/// [`TRACE_GROWTH`]) and the lock-in's thermal noise at every point ([`NOISE_PERIODS`]).
///
/// # Errors
/// [`SimError::Params`] when the model cannot be built.
pub(crate) fn stepped_cost(spec: &SteppedSpec) -> Result<Cost, SimError> {
    let p = &spec.base;
    let points = spec.values.len() as f64;
    let ways = if spec.branches { 2.0 } else { 1.0 };
    // a time-averaged curve (a quasi-periodic drive, or asked for) runs its quasi-periodic
    // model to its transient cap and then its measured windows
    let search = match &spec.average {
        Some(avg) => {
            let model = CantileverModel::quasiperiodic(p)?;
            (spec.steady.cap(&model) + avg.windows * avg.window_periods) as f64 * p.modes as f64
        }
        None => steady_periods(&spec.steady, p)? * p.modes as f64,
    };
    let branch = match spec.branches {
        true => {
            spec.max_branch_points as f64 * newton_work(p, spec.steady.max_period, &spec.newton)
        }
        false => 0.0,
    };
    let traces = match spec.trace_samples {
        0 => 0.0,
        n => TRACE_GROWTH * super::curves::trace_bytes(spec.values.len(), n),
    };
    // a point: its state, observables and orbit (a few hundred bytes)
    let point = 4.0 * state_bytes(p) + 512.0;
    // the lock-in's thermal noise at every point of both sweeps: a (common) period of
    // variational flows in 512 parts per drive period and the chain's products, whose size
    // 2N + 4L with L lock-ins (one per drive component) is at most L times one lock-in's
    // (crate::analysis::lock_in_noise)
    let chain = (p.demodulated().len() as f64).powi(3) * p.common_periods() as f64;
    let noise = match spec.noise {
        Some(_) => 2.0 * points * NOISE_PERIODS * p.modes as f64 * chain,
        None => 0.0,
    };
    Ok(Cost {
        bytes: MODEL_BYTES + ways * points * point + traces,
        work: ways * points * search + branch + noise,
    })
}

/// The cost of a basin map: every cell integrated up to its transient cap; a cell's class
/// kept (64 bytes) and each attractor's Poincaré points.
///
/// # Errors
/// [`SimError::Params`] when the model cannot be built.
pub(crate) fn basins_cost(spec: &BasinSpec) -> Result<Cost, SimError> {
    let p = &spec.params;
    let cells = spec.xs.len() as f64 * spec.ys.len() as f64;
    Ok(Cost {
        bytes: MODEL_BYTES + cells * 64.0,
        work: cells * steady_periods(&spec.steady, p)? * p.modes as f64,
    })
}

/// Runs of a chart's cell in the worst case its options allow: its K random starts and, by
/// continuation, the attractors of its two neighbours (about K each).
pub(crate) const CHART_RUNS_PER_START: f64 = 3.0;

/// The cost of a behaviour chart of `spec` (its cells' parameters by `params(x, y)`, up to
/// `slots` attractors a cell): cells × starts (and the
/// neighbours' attractors continued into each cell, [`CHART_RUNS_PER_START`]) × the transient
/// cap × modes, the largest cap of its four corners (the decay rates vary monotonically
/// along each axis); a λ₁ of `lyapunov_periods` of the state and one tangent vector per
/// attractor found; every cell's attractors kept (up to its slots: 128 bytes each and their
/// 10 array values).
///
/// # Errors
/// [`SimError`] when a corner's parameters do not build a model.
pub(crate) fn chart_cost(
    spec: &crate::analysis::chart::ChartSpec,
    slots: usize,
    params: &dyn Fn(f64, f64) -> Result<crate::params::Params, SimError>,
) -> Result<Cost, SimError> {
    let (xs, ys) = (&spec.x, &spec.y);
    let mut cap: f64 = 0.0;
    for (x, y) in corners(spec) {
        let p = params(x, y)?;
        let periods = steady_periods(&spec.steady, &p)? + 2.0 * spec.lyapunov_periods as f64;
        cap = cap.max(periods * p.modes as f64);
    }
    let cells = xs.len() as f64 * ys.len() as f64;
    let runs = cells * f64::from(spec.starts) * CHART_RUNS_PER_START;
    Ok(Cost {
        bytes: MODEL_BYTES + cells * (128.0 + slots as f64 * (128.0 + 80.0)),
        work: runs * cap,
    })
}

/// The four corners (x, y) of a chart of `spec`: where its cost and its integrator are checked
/// (a model's decay rates vary monotonically along each axis).
pub(crate) fn corners(spec: &crate::analysis::chart::ChartSpec) -> [(f64, f64); 4] {
    let (xs, ys) = (&spec.x, &spec.y);
    let (x1, y1) = (xs[xs.len() - 1], ys[ys.len() - 1]);
    [(xs[0], ys[0]), (x1, ys[0]), (xs[0], y1), (x1, y1)]
}

/// The cost of an image's approach curves ([`crate::request::image`]): one curve of
/// `curve_points` each way per material (`materials`: the background and every domain with a
/// sample of its own) on the probe's model `params` (the lever's decay, hence the transient
/// cap, is the same for every material), in length unit `length`.
///
/// # Errors
/// As the approach curve's request.
pub(crate) fn image_curves_cost(
    params: Params,
    length: f64,
    curve_points: usize,
    materials: usize,
) -> Result<Cost, SimError> {
    let curve = super::curves::CurveRequest {
        points: Some(curve_points),
        branches: false,
        ..super::curves::CurveRequest::default()
    };
    let one = stepped_cost(&super::curves::approach_request(
        params, &curve, length, false,
    )?)?;
    let m = materials as f64;
    Ok(Cost {
        bytes: m * one.bytes,
        work: m * one.work,
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use crate::error::SimError;
    use crate::params::Params;
    use crate::request::{ChartRequest, ModelSpec};

    /// `e` is a budget refusal of `what`, naming it.
    pub(crate) fn refused_as(e: SimError, what: &str) {
        match &e {
            SimError::Budget { what: w, .. } => assert_eq!(*w, what, "{e}"),
            other => panic!("not a budget refusal: {other}"),
        }
        assert!(e.to_string().contains(what), "{e}");
    }

    /// A chart beyond the work budget (10⁶ cells × 10 starts) is refused as it is built,
    /// before any cell runs (the refusal is immediate), naming the chart.
    #[test]
    fn a_chart_beyond_the_budget_is_refused_before_any_work() {
        let request = ChartRequest {
            x_steps: 1000,
            y_steps: 1000,
            starts: 10,
            ..ChartRequest::default()
        };
        let e = request
            .chart(ModelSpec::default(), Params::default(), None)
            .unwrap_err();
        refused_as(e, "chart");
        // the default chart is within it
        assert!(ChartRequest::default()
            .chart(ModelSpec::default(), Params::default(), None)
            .is_ok());
    }
}

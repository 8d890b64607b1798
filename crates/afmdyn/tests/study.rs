//! Studies planned as independent tasks (issue 29): the bifurcation sweep cut into chain
//! segments seeded by a coarse pass, and the two-parameter behaviour chart cut into tiles.
//! Every task is a pure function of the request and its number: results do not depend on the
//! thread count or the order the tasks run in.

use afmdyn::analysis::attractors::{find_attractors, same_attractor, AttractorSpec};
use afmdyn::analysis::bifurcation::{run_sweep, Branch, Resume, SweepPlan, SweepPoint, SweepSpec};
use afmdyn::analysis::chart::{run_chart, CellParams, ChartCell, ChartPlan};
use afmdyn::analysis::progress::Progress;
use afmdyn::analysis::steady::{steady_state, SteadyOptions};
use afmdyn::integrate::{build, IntegratorOptions};
use afmdyn::probe::Probe;
use afmdyn::request::chart::axis_name;
use afmdyn::request::{ChartRequest, ModelSpec};
use afmdyn::{CantileverModel, Params, SweepParam};
use nalgebra::DVector;
use std::collections::HashSet;
use std::sync::atomic::AtomicBool;
use std::sync::Mutex;

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
}

fn sweep(values: Vec<f64>, starts: u32) -> SweepSpec {
    SweepSpec {
        base: Params::default(),
        param: SweepParam::Omega,
        values,
        continuation: true,
        starts,
        seed: 5,
        steady: SteadyOptions::default(),
        integrator: IntegratorOptions::default(),
    }
}

fn sorted_points(spec: &SweepSpec, threads: usize) -> Vec<(usize, Branch, String)> {
    let seen = Mutex::new(Vec::new());
    pool(threads).install(|| {
        run_sweep(spec, &Resume::default(), &|p: SweepPoint| {
            // the whole result, bit for bit (Debug prints every f64 exactly)
            seen.lock()
                .unwrap()
                .push((p.index, p.branch, format!("{:?}", p.result)))
        })
    });
    let mut all = seen.into_inner().unwrap();
    all.sort_by_key(|(i, b, _)| (*i, *b));
    all
}

/// A default-size sweep (400 values) plans at least 32 tasks, and 1 and 2 threads give the
/// same points bit for bit.
#[test]
fn a_sweep_is_many_tasks_and_its_points_do_not_depend_on_threads() {
    let spec = sweep(SweepSpec::linspace(1.0, 5.0, 400).unwrap(), 0);
    let plan = SweepPlan::new(&spec);
    assert!(plan.tasks(1).len() >= 32, "{} tasks", plan.tasks(1).len());
    assert_eq!(plan.tasks(0).len(), 2, "one coarse pass per branch");
    // every value of each branch in exactly one chunk, in the branch's order
    for b in [Branch::Forward, Branch::Backward] {
        let all: Vec<usize> = (0..plan.chunks())
            .flat_map(|k| plan.chunk_indices(b, k))
            .collect();
        let expect: Vec<usize> = match b {
            Branch::Forward => (0..400).collect(),
            _ => (0..400).rev().collect(),
        };
        assert_eq!(all, expect);
    }
    let small = sweep(SweepSpec::linspace(2.0, 4.0, 40).unwrap(), 1);
    let one = sorted_points(&small, 1);
    assert_eq!(one.len(), 120);
    assert_eq!(one, sorted_points(&small, 2));
}

/// Where the branch a chain follows is a stable periodic orbit over the whole range, the
/// segmented forward continuation gives the sequential chain's steady states (written here
/// independently: one steady state after the other, each from the last one's end state):
/// the same periods, and Poincaré points equal to within the steady-state tolerance.
#[test]
fn segments_follow_the_sequential_chain_on_a_periodic_branch() {
    // Ω from 3.0 to 4.5: the default model's period-1 and period-2 orbits (paper Fig. 5), no
    // chaos, no coexistence along the forward path
    let values = SweepSpec::linspace(3.0, 4.5, 64).unwrap();
    let spec = sweep(values.clone(), 0);
    let segmented = Mutex::new(Vec::new());
    run_sweep(&spec, &Resume::default(), &|p| {
        if p.branch == Branch::Forward {
            segmented.lock().unwrap().push(p);
        }
    });
    let mut segmented = segmented.into_inner().unwrap();
    segmented.sort_by_key(|p| p.index);
    let mut z = DVector::zeros(2 * spec.base.modes);
    let mut compared = 0;
    for (i, &v) in values.iter().enumerate() {
        let m = CantileverModel::new(&spec.base.with(SweepParam::Omega, v)).unwrap();
        let mut it = build(&m, spec.integrator.clone(), 0.0, &z).unwrap();
        let s = steady_state(it.as_mut(), &spec.steady).unwrap();
        z = s.end_state().clone();
        let t = segmented[i].result.as_ref().unwrap();
        assert_eq!(t.period(), s.period(), "Ω = {v}");
        if let (Some(_), Some(p)) = (s.period(), t.poincare.first()) {
            let near = s
                .poincare
                .iter()
                .any(|q| (&q.state - &p.state).norm() <= 1e-5 * (1.0 + q.state.norm()));
            assert!(near, "Ω = {v}: another orbit");
            compared += 1;
        }
    }
    assert!(compared > 50, "{compared}");
}

/// A random start is keyed by its value, not its index: a sweep over a sub-range gives the
/// same start (and steady state) at a shared value.
#[test]
fn random_starts_are_keyed_by_the_value() {
    let start_of = |values: Vec<f64>, at: usize| {
        let mut spec = sweep(values, 1);
        spec.continuation = false;
        let seen = Mutex::new(None);
        run_sweep(&spec, &Resume::default(), &|p| {
            if p.index == at {
                *seen.lock().unwrap() = Some(format!("{:?}", p.result));
            }
        });
        seen.into_inner().unwrap().unwrap()
    };
    assert_eq!(
        start_of(vec![3.1, 3.3, 3.5], 1),
        start_of(vec![3.3, 3.9], 0)
    );
}

/// The chart's default axes over the paper's default model.
struct OmegaDrive;

impl CellParams for OmegaDrive {
    fn params(&self, x: f64, y: f64) -> Result<Params, afmdyn::SimError> {
        Ok(Params {
            omega: x,
            alpha2: y,
            ..Params::default()
        })
    }
}

fn chart_cells(
    req: &ChartRequest,
    cells: &dyn CellParams,
    threads: usize,
) -> (Vec<ChartCell>, usize) {
    let chart = req
        .chart(ModelSpec::default(), Params::default(), None)
        .unwrap();
    let plan = ChartPlan::new(&chart.spec, cells);
    let out = Mutex::new(Vec::new());
    pool(threads).install(|| {
        run_chart(
            &plan,
            &HashSet::new(),
            &|_, c| out.lock().unwrap().extend(c),
            &AtomicBool::new(false),
        )
    });
    let mut out = out.into_inner().unwrap();
    out.sort_by_key(|c| (c.iy, c.ix));
    (out, plan.tasks())
}

/// The chart's cells do not depend on the thread count nor on the order its tasks run in
/// (each task run alone, last first, gives the same cells).
#[test]
fn chart_cells_do_not_depend_on_threads_or_task_order() {
    let req = ChartRequest {
        x_steps: 5,
        y_steps: 2,
        starts: 2,
        tile: 3,
        lyapunov_periods: 50,
        ..ChartRequest::default()
    };
    let (one, tasks) = chart_cells(&req, &OmegaDrive, 1);
    assert_eq!(tasks, 4, "⌈5/3⌉ tiles × 2 rows");
    assert_eq!(one.len(), 10);
    let (two, _) = chart_cells(&req, &OmegaDrive, 2);
    assert_eq!(format!("{one:?}"), format!("{two:?}"));
    let chart = req
        .chart(ModelSpec::default(), Params::default(), None)
        .unwrap();
    let plan = ChartPlan::new(&chart.spec, &OmegaDrive);
    let mut alone: Vec<ChartCell> = (0..plan.tasks())
        .rev()
        .flat_map(|t| plan.run_task(t, &AtomicBool::new(false)).unwrap())
        .collect();
    alone.sort_by_key(|c| (c.iy, c.ix));
    assert_eq!(format!("{one:?}"), format!("{alone:?}"));
}

/// Every attractor a chart cell reports is one the attractor census (64 random starts,
/// independent of the chart) finds at the same parameters, or a periodic orbit that shooting
/// confirms; the basin fractions of the random starts add up to the starts that converged.
#[test]
fn chart_attractors_are_real_and_their_fractions_add_up() {
    let req = ChartRequest {
        x_from: 2.7,
        x_to: 2.8,
        x_steps: 3,
        y_from: 0.1,
        y_to: 0.1,
        y_steps: 1,
        starts: 4,
        lyapunov_periods: 0,
        ..ChartRequest::default()
    };
    let (cells, _) = chart_cells(&req, &OmegaDrive, 2);
    let mut coexisting = 0;
    for c in &cells {
        let sum: f64 = c.attractors.iter().map(|a| a.fraction).sum();
        let converged = f64::from(req.starts - c.failures.min(req.starts)) / f64::from(req.starts);
        assert!((sum - converged).abs() < 1e-12, "{c:?}");
        let p = OmegaDrive.params(c.x, c.y).unwrap();
        let census = find_attractors(
            &AttractorSpec {
                params: p,
                samples: 64,
                seed: 9,
                cluster_tol: 1e-5,
                steady: SteadyOptions::default(),
                integrator: IntegratorOptions::default(),
            },
            &Progress::new(),
        )
        .unwrap();
        let m = CantileverModel::new(&p).unwrap();
        for a in &c.attractors {
            let z = DVector::from_vec(a.state.clone());
            let mut it = build(&m, IntegratorOptions::default(), 0.0, &z).unwrap();
            let s = steady_state(it.as_mut(), &SteadyOptions::default()).unwrap();
            assert_eq!(s.period(), a.period, "{c:?}");
            assert!(
                census
                    .attractors
                    .iter()
                    .any(|b| same_attractor(&b.steady, &s, 1e-4)),
                "Ω = {}: period {:?} not in the census",
                c.x,
                a.period
            );
        }
        coexisting += usize::from(c.attractors.len() > 1);
    }
    assert!(coexisting >= 1, "{cells:?}");
}

/// An axis is named by the library's name, the paper's alias or with hyphens, and a cell's
/// parameters are those of a single run with the two values given; with a probe, z_c in m.
#[test]
fn chart_axes_resolve_like_a_single_run() {
    assert_eq!(axis_name("x", "alpha2").unwrap(), "drive_amplitude");
    assert_eq!(
        axis_name("x", "Drive-Amplitude").unwrap(),
        "drive_amplitude"
    );
    assert_eq!(axis_name("x", "omega").unwrap(), "omega");
    assert!(axis_name("x", "modes").is_err());
    assert!(axis_name("x", "contact_law").is_err());
    let req = ChartRequest {
        x: "gap".into(),
        x_from: 0.5,
        x_to: 1.0,
        y: "alpha4".into(),
        y_from: 10.0,
        y_to: 30.0,
        ..ChartRequest::default()
    };
    let chart = req
        .chart(ModelSpec::default(), Params::default(), None)
        .unwrap();
    let p = chart.model.params(0.75, 20.0).unwrap();
    assert_eq!(
        p,
        Params {
            alpha5: 0.75,
            alpha4: 20.0,
            ..Params::default()
        }
    );
    // a value out of its parameter's range on an edge is refused before anything runs
    let bad = ChartRequest {
        y_from: -1.0,
        ..req.clone()
    };
    assert!(bad
        .chart(ModelSpec::default(), Params::default(), None)
        .is_err());
    // with a probe: z_c in m, resolved as `ModelSpec { z_c }` is
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/probe-point-mass-dmt.toml"
    ))
    .unwrap();
    let probe = Probe::parse(&text, "probe").unwrap();
    let req = ChartRequest {
        x: "z_c".into(),
        x_from: 5e-9,
        x_to: 10e-9,
        y: "drive_frequency".into(),
        y_from: 0.99 * probe.drive_frequency,
        y_to: 1.01 * probe.drive_frequency,
        ..ChartRequest::default()
    };
    let chart = req
        .chart(ModelSpec::default(), Params::default(), Some(&text))
        .unwrap();
    let single = ModelSpec {
        z_c: Some(7e-9),
        drive_frequency: Some(probe.drive_frequency),
        ..ModelSpec::default()
    }
    .resolve(Params::default(), Some(&probe))
    .unwrap();
    assert_eq!(
        chart.model.params(7e-9, probe.drive_frequency).unwrap(),
        single
    );
    // a value of the probe file as an axis: the cell's parameters are those of the file with
    // that value written in it (here A₀ = 12 nm and E_s = 2 GPa, edited as text)
    let req = ChartRequest {
        x: "free-amplitude".into(),
        x_from: 8e-9,
        x_to: 14e-9,
        y: "sample_modulus".into(),
        y_from: 1e9,
        y_to: 3e9,
        ..ChartRequest::default()
    };
    let chart = req
        .chart(ModelSpec::default(), Params::default(), Some(&text))
        .unwrap();
    let edited = text
        .replace("free_amplitude = 10e-9", "free_amplitude = 12e-9")
        .replace("youngs_modulus = 4e9", "youngs_modulus = 2e9");
    assert_ne!(edited, text);
    let by_hand = Probe::parse(&edited, "edited").unwrap().params;
    assert_eq!(chart.model.params(12e-9, 2e9).unwrap(), by_hand);
    assert_eq!(afmdyn::request::chart::axis_unit("sample_modulus"), "Pa");
    // without a probe, a probe value is refused with the reason
    let e = req
        .chart(ModelSpec::default(), Params::default(), None)
        .unwrap_err();
    assert!(e.to_string().contains("probe"), "{e}");
    let req = ChartRequest {
        x: "z_c".into(),
        x_from: 5e-9,
        x_to: 10e-9,
        y: "drive_frequency".into(),
        y_from: 0.99 * probe.drive_frequency,
        y_to: 1.01 * probe.drive_frequency,
        ..ChartRequest::default()
    };
    // without a probe, z_c is refused with the reason
    let e = req
        .chart(ModelSpec::default(), Params::default(), None)
        .unwrap_err();
    assert!(e.to_string().contains("probe"), "{e}");
}

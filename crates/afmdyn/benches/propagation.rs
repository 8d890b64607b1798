//! Throughput of the integrators: forcing periods per second at the default parameters
//! (paper eq. 26, Ω = 2.6) for N = 1, 3, 5, 10, 20 (linear law, exact propagator, through
//! `advance`; the observed step loop `advance_dyn` and the dense and modal paths forced at
//! N = 3 and 10 for comparison), the adaptive
//! integrator with the Hertz and DMT laws (tolerance 1e-12) for N = 1, 3, and exact against RK4
//! at matched accuracy (state at τ = 40 within 1e-8 of the exact answer).
//!
//! Run with `cargo bench -p afmdyn`; the matched-accuracy step count of RK4 is printed.

use afmdyn::integrate::exact::{ExactOptions, ExactPropagator, Propagation};
use afmdyn::integrate::{
    advance, advance_dyn, build, Integrator, IntegratorKind, IntegratorOptions,
};
use afmdyn::{CantileverModel, ContactLaw, Params};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use nalgebra::DVector;
use std::hint::black_box;

const PERIODS: usize = 100;

fn run(
    model: &CantileverModel,
    opts: IntegratorOptions,
    z0: &DVector<f64>,
    tau_end: f64,
) -> DVector<f64> {
    let mut it = build(model, opts, 0.0, z0).expect("build");
    advance_dyn(it.as_mut(), tau_end, &mut |_, _, _| Ok(())).expect("run");
    it.state().clone()
}

fn exact() -> IntegratorOptions {
    IntegratorOptions {
        kind: IntegratorKind::Exact,
        steps_per_period: 1,
        tolerance: 1e-12, // ignored here, but every tolerance is in [1e-16, 1e-3]
        ..IntegratorOptions::default()
    }
}

/// The default model with `n` modes and a state on its attractor (after 100 periods from rest,
/// so that the contacts per period are representative): (model, τ0, z0, τ0 + PERIODS T).
fn on_attractor(n: usize) -> (CantileverModel, f64, DVector<f64>, f64) {
    let p = Params {
        modes: n,
        ..Params::default()
    };
    let m = CantileverModel::new(&p).unwrap();
    let t0 = 100.0 * p.period();
    let z0 = run(&m, exact(), &m.rest(), t0);
    (m, t0, z0, t0 + PERIODS as f64 * p.period())
}

fn periods_per_second(c: &mut Criterion) {
    let mut g = c.benchmark_group("exact periods");
    g.throughput(Throughput::Elements(PERIODS as u64));
    for n in [1usize, 3, 5, 10, 20] {
        let (m, t0, z0, t1) = on_attractor(n);
        let mut it = build(&m, exact(), t0, &z0).unwrap();
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                it.reset(t0, &z0).unwrap();
                advance(it.as_mut(), t1).unwrap();
                black_box(it.state()[0])
            })
        });
    }
    g.finish();
}

fn paths(c: &mut Criterion) {
    let mut g = c.benchmark_group("exact paths");
    g.throughput(Throughput::Elements(PERIODS as u64));
    for n in [3usize, 10] {
        let (m, t0, z0, t1) = on_attractor(n);
        for (name, propagation) in [("dense", Propagation::Dense), ("modal", Propagation::Auto)] {
            let opts = ExactOptions {
                propagation,
                ..ExactOptions::default()
            };
            let mut it = ExactPropagator::try_with(&m, opts).unwrap();
            g.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
                b.iter(|| {
                    it.reset(t0, &z0).unwrap();
                    advance(&mut it, t1).unwrap();
                    black_box(it.state()[0])
                })
            });
        }
        let mut it = build(&m, exact(), t0, &z0).unwrap();
        g.bench_with_input(BenchmarkId::new("observed", n), &n, |b, _| {
            b.iter(|| {
                it.reset(t0, &z0).unwrap();
                advance_dyn(it.as_mut(), t1, &mut |_, _, _| Ok(())).unwrap();
                black_box(it.state()[0])
            })
        });
    }
    g.finish();
}

fn matched_accuracy(c: &mut Criterion) {
    let p = Params::default();
    let m = CantileverModel::new(&p).unwrap();
    let z0 = m.rest();
    let reference = run(&m, exact(), &z0, 40.0);
    let mut steps = 100;
    let rk4 = |s| IntegratorOptions {
        kind: IntegratorKind::Rk4,
        steps_per_period: s,
        tolerance: 1e-12, // ignored here, but every tolerance is in [1e-16, 1e-3]
        ..IntegratorOptions::default()
    };
    while (run(&m, rk4(steps), &z0, 40.0) - &reference).amax() > 1e-8 {
        steps = steps * 5 / 4;
    }
    let err = (run(&m, rk4(steps), &z0, 40.0) - &reference).amax();
    println!("rk4 needs {steps} steps per period for |z(40) - exact| = {err:.2e} <= 1e-8");
    let periods = 40.0 / p.period();
    let mut g = c.benchmark_group("tau 0..40 at 1e-8");
    g.throughput(Throughput::Elements(periods.round() as u64));
    g.bench_function("exact", |b| {
        b.iter(|| black_box(run(&m, exact(), &z0, 40.0)))
    });
    g.bench_function(format!("rk4 ({steps} steps/period)"), |b| {
        b.iter(|| black_box(run(&m, rk4(steps), &z0, 40.0)))
    });
    g.finish();
}

fn nonlinear_laws(c: &mut Criterion) {
    let mut g = c.benchmark_group("adaptive periods");
    g.throughput(Throughput::Elements(20));
    let adaptive = IntegratorOptions {
        kind: IntegratorKind::Adaptive,
        steps_per_period: 1,
        tolerance: 1e-12,
        ..IntegratorOptions::default()
    };
    for (name, law) in [
        ("hertz", ContactLaw::Hertz),
        (
            "dmt",
            ContactLaw::Dmt {
                hamaker: 1e-5,
                intermolecular_distance: 0.01,
            },
        ),
    ] {
        for n in [1usize, 3] {
            let p = Params {
                modes: n,
                contact_law: law,
                ..Params::default()
            };
            let m = CantileverModel::new(&p).unwrap();
            let t0 = 50.0 * p.period();
            let z0 = run(&m, adaptive.clone(), &m.rest(), t0);
            let mut it = build(&m, adaptive.clone(), t0, &z0).unwrap();
            g.bench_with_input(BenchmarkId::new(name, n), &n, |b, _| {
                b.iter(|| {
                    it.reset(t0, &z0).unwrap();
                    advance_dyn(it.as_mut(), t0 + 20.0 * p.period(), &mut |_, _, _| Ok(()))
                        .unwrap();
                    black_box(it.state()[0])
                })
            });
        }
    }
    g.finish();
}

criterion_group!(
    benches,
    periods_per_second,
    paths,
    nonlinear_laws,
    matched_accuracy
);
criterion_main!(benches);

//! Shooting and continuation cost: one Newton shooting solve of the period-1 orbit at N = 3
//! (Ω = 3.5, from the attractor perturbed by 1e-3), and the continuation of the default
//! period-1 branch over Ω from 5 down to 1 (paper eq. 26 set).
//!
//! Run with `cargo bench -p afmdyn --bench stability`.

use afmdyn::analysis::continuation::{continue_branch, ContinuationSpec};
use afmdyn::analysis::progress::Progress;
use afmdyn::analysis::shooting::{shoot, ShootingOptions};
use afmdyn::analysis::steady::{steady_state, SteadyOptions};
use afmdyn::integrate::{build, IntegratorOptions};
use afmdyn::maps::StroboscopicMap;
use afmdyn::{CantileverModel, Params, SweepParam};
use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::DVector;
use std::hint::black_box;
use std::time::Duration;

fn attractor(p: &Params) -> DVector<f64> {
    let m = CantileverModel::new(p).unwrap();
    let mut it = build(&m, IntegratorOptions::default(), 0.0, &m.rest()).unwrap();
    steady_state(it.as_mut(), &SteadyOptions::default())
        .unwrap()
        .end_state()
        .clone()
}

fn shooting(c: &mut Criterion) {
    let p = Params {
        omega: 3.5,
        ..Params::default()
    };
    let m = CantileverModel::new(&p).unwrap();
    let guess = attractor(&p) + DVector::from_element(6, 1e-3);
    // one build and one solve per iteration, the builds sharing one propagator cache (as the
    // builds of one request do)
    let opts = IntegratorOptions::default();
    let solve = || {
        let mut it = build(&m, opts.clone(), 0.0, &m.rest()).unwrap();
        let map = &mut StroboscopicMap::new(it.as_mut(), 1);
        shoot(map, &guess, &ShootingOptions::default()).unwrap()
    };
    let iters = solve().residuals.len();
    println!("shooting: {iters} residual evaluations (Newton iterations + 1)");
    c.bench_function("shoot period-1, N = 3", |b| b.iter(|| black_box(solve())));
}

fn continuation(c: &mut Criterion) {
    let base = Params::default();
    let guess = attractor(&Params { omega: 5.0, ..base });
    let spec = ContinuationSpec::new(base, SweepParam::Omega, 5.0, 1.0, 1);
    let n = continue_branch(&spec, &guess, &Progress::new())
        .unwrap()
        .len();
    println!("continuation Ω 5 → 1: {n} points");
    let mut g = c.benchmark_group("continuation");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(100))
        .measurement_time(Duration::from_secs(20));
    g.bench_function("period-1 branch, Ω 5 → 1", |b| {
        b.iter(|| {
            black_box(
                continue_branch(&spec, &guess, &Progress::new())
                    .unwrap()
                    .len(),
            )
        })
    });
    g.finish();
}

criterion_group!(benches, shooting, continuation);
criterion_main!(benches);

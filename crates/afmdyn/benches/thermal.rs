//! The thermal spectrum's cost (issue 79's aim: ≤ 0.1 s): the PSD of an N = 10 beam (the
//! paper's default set at N = 10, model units) over 0–5 f₀ at 10⁵ frequencies.
//!
//! And the thermally driven free lever's cost per period (issue 79's aim: ≤ 2× the
//! deterministic propagator's): the paper's default lever (N = 3 and 10) with the sample out of
//! reach (α5 = 50), 100 periods (the exact propagator's grid, 16 steps per period at least), by
//! the deterministic exact propagator and by the exact stochastic step (`ThermalExact`,
//! k_B T = 10⁻⁴ in the model's energy unit) holding one point per period, the stroboscopic
//! section's (free flight between them).
//!
//! Run with `cargo bench -p afmdyn --bench thermal`.

use afmdyn::analysis::progress::Progress;
use afmdyn::analysis::thermal::{thermal_spectrum, ModelUnits};
use afmdyn::integrate::exact::{ThermalExact, ThermalForce};
use afmdyn::integrate::{advance, build, Integrator, IntegratorKind, IntegratorOptions};
use afmdyn::{CantileverModel, Params};
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use std::time::Duration;

fn spectrum(c: &mut Criterion) {
    let p = Params {
        modes: 10,
        ..Params::default()
    };
    let one = ModelUnits {
        length_m: 1.0,
        force_n: 1.0,
        time_s: 1.0,
    };
    let f0 = thermal_spectrum(&p, one, 295.0, 1.0, &[], &Progress::default())
        .unwrap()
        .modes[0]
        .frequency;
    let freqs: Vec<f64> = (1..=100_000).map(|i| 5.0 * f0 * i as f64 / 1e5).collect();
    let mut g = c.benchmark_group("thermal");
    g.sample_size(10).measurement_time(Duration::from_secs(5));
    g.bench_function("psd_n10_1e5_frequencies", |b| {
        b.iter(|| {
            black_box(thermal_spectrum(&p, one, 295.0, 1.0, &freqs, &Progress::default()).unwrap())
        })
    });
    g.finish();
}

fn free_lever(c: &mut Criterion) {
    let mut g = c.benchmark_group("thermal free lever, 100 periods");
    g.sample_size(20).measurement_time(Duration::from_secs(5));
    for n in [3usize, 10] {
        let p = Params {
            modes: n,
            alpha5: 50.0,
            ..Params::default()
        };
        let m = CantileverModel::new(&p).unwrap();
        let opts = IntegratorOptions {
            kind: IntegratorKind::Exact,
            steps_per_period: 16,
            ..IntegratorOptions::default()
        };
        let end = 100.0 * p.period();
        let mut det = build(&m, opts.clone(), 0.0, &m.rest()).unwrap();
        g.bench_function(format!("deterministic N={n}"), |b| {
            b.iter(|| {
                det.reset(0.0, &m.rest()).unwrap();
                advance(det.as_mut(), end).unwrap();
                black_box(det.state()[0])
            })
        });
        // one held point per period (the stroboscopic section's): free flight between them
        let mut th = ThermalExact::new(&m, &opts, ThermalForce::new(1e-4, 7))
            .unwrap()
            .holding(1);
        // (scripts/perf-thermal.sh reads the grid from this line)
        eprintln!("N = {n}: {} grid steps per period", th.steps_per_period());
        g.bench_function(format!("thermal N={n}"), |b| {
            b.iter(|| {
                th.reset(0.0, &m.rest()).unwrap();
                advance(&mut th, end).unwrap();
                black_box(th.state()[0])
            })
        });
    }
    g.finish();
}

criterion_group!(benches, spectrum, free_lever);
criterion_main!(benches);

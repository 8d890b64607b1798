//! The thermal spectrum's cost (issue 79's aim: ≤ 0.1 s): the PSD of an N = 10 beam (the
//! paper's default set at N = 10, model units) over 0–5 f₀ at 10⁵ frequencies.
//!
//! Run with `cargo bench -p afmdyn --bench thermal`.

use afmdyn::analysis::progress::Progress;
use afmdyn::analysis::thermal::{thermal_spectrum, ModelUnits};
use afmdyn::Params;
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

criterion_group!(benches, spectrum);
criterion_main!(benches);

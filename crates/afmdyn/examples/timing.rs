//! Wall-clock timings of the library alone, the reference of the Python overhead benchmark
//! (`crates/afmdyn-py/bench/overhead.py`):
//!
//! ```sh
//! cargo run --release -p afmdyn --example timing -- simulate 1000 5   # 1000 periods, best of 5
//! cargo run --release -p afmdyn --example timing -- bifurcation 5     # default sweep, best of 5
//! ```
//!
//! `simulate` records what `afmdyn simulate` records (200 samples per period, energy balance,
//! body-contact check) from rest at the default parameters; `bifurcation` runs the default
//! sweep (Ω from 1 to 5, 400 values, forward and backward) and keeps every point in memory.
//! Prints one line of JSON with the best time in seconds.

use afmdyn::analysis::bifurcation::{run_sweep, Resume, SweepPoint, SweepSpec};
use afmdyn::analysis::steady::SteadyOptions;
use afmdyn::integrate::{build, IntegratorOptions};
use afmdyn::trajectory::{record, RecordSpec};
use afmdyn::{CantileverModel, Params, SweepParam};
use std::sync::Mutex;
use std::time::Instant;

fn best(repeats: usize, mut f: impl FnMut() -> usize) -> (f64, usize) {
    let mut t = f64::INFINITY;
    let mut size = 0;
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        size = f();
        t = t.min(start.elapsed().as_secs_f64());
    }
    (t, size)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let what = args.first().map_or("simulate", String::as_str);
    let num =
        |i: usize, default: usize| args.get(i).and_then(|s| s.parse().ok()).unwrap_or(default);
    let p = Params::default();
    match what {
        "simulate" => {
            let periods = num(1, 1000);
            let (t, samples) = best(num(2, 5), || {
                let model = CantileverModel::new(&p).expect("params");
                let opts = IntegratorOptions {
                    steps_per_period: 200,
                    ..IntegratorOptions::default()
                };
                let mut integ = build(&model, opts, 0.0, &model.rest()).expect("integrator");
                let tr = record(
                    integ.as_mut(),
                    &RecordSpec {
                        transient_periods: 0.0,
                        record_tau: periods as f64 * p.period(),
                        samples_per_period: 200,
                        energy: true,
                        body_contact: true,
                    },
                )
                .expect("run");
                tr.samples.len()
            });
            println!("{{\"what\":\"simulate\",\"periods\":{periods},\"samples\":{samples},\"seconds\":{t}}}");
        }
        "bifurcation" => {
            let spec = SweepSpec {
                base: p,
                param: SweepParam::Omega,
                values: SweepSpec::linspace(1.0, 5.0, 400).expect("values"),
                continuation: true,
                starts: 0,
                seed: 1,
                steady: SteadyOptions::default(),
                integrator: IntegratorOptions::default(),
            };
            let (t, points) = best(num(1, 5), || {
                let pool = rayon::ThreadPoolBuilder::new().build().expect("pool");
                let found = Mutex::new(Vec::new());
                let sink = |pt: SweepPoint| found.lock().expect("points").push(pt);
                pool.install(|| run_sweep(&spec, &Resume::default(), &sink));
                found.into_inner().expect("points").len()
            });
            println!("{{\"what\":\"bifurcation\",\"points\":{points},\"seconds\":{t}}}");
        }
        other => {
            eprintln!("timing: unknown benchmark '{other}' (simulate or bifurcation)");
            std::process::exit(2);
        }
    }
}

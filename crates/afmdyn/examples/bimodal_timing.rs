//! Cost of a bimodal approach curve: the exact periodic orbits of the common period
//! ([`afmdyn::analysis::stepped::stepped_sweep`] on a multifrequency drive: both sweeps, 200
//! orbits, no branches) against
//! the time-domain way of VEDA-like simulators — at each z_c the motion integrated on from the
//! previous value's end state, each component demodulated over windows of 25 common periods
//! ([`afmdyn::analysis::observables::observe`]), until two successive windows agree to 1e-6 of
//! each free amplitude — over the approach's 100 z_c values of the default range, on
//! `examples/probe-bimodal.toml`:
//!
//! ```sh
//! cargo run --release -p afmdyn --example bimodal_timing
//! ```
//!
//! Prints one line of JSON: seconds of each, their ratio, the drive periods the time domain
//! integrated, and the largest difference of the components' amplitudes relative to their free
//! amplitudes.

use afmdyn::analysis::approach::{approach_spec, default_range};
use afmdyn::analysis::observables::{observe, ObservableOptions};
use afmdyn::analysis::stepped::{stepped_sweep, Spacing};
use afmdyn::integrate::build;
use afmdyn::probe::Probe;
use afmdyn::{CantileverModel, IntegratorOptions};
use std::path::Path;
use std::time::Instant;

/// Common periods per demodulation window, and the most windows per z_c.
const WINDOW: usize = 25;
const MAX_WINDOWS: usize = 400;

fn main() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/probe-bimodal.toml");
    let probe = Probe::load(&path).expect("example probe");
    let p = probe.params;
    let (far, near) = default_range(&p).expect("range");
    let mut spec = approach_spec(p, far, near, Spacing::Points(100)).expect("spec");
    spec.branches = false;
    let t = Instant::now();
    let exact = stepped_sweep(&spec).expect("exact");
    let t_exact = t.elapsed().as_secs_f64();

    // the time domain: one integrator per value, from the previous value's end state
    let opts = IntegratorOptions {
        tolerance: spec.integrator.tolerance,
        ..IntegratorOptions::default()
    };
    let window = ObservableOptions {
        periods: WINDOW,
        harmonics: 1,
    };
    let t = Instant::now();
    let mut state = CantileverModel::new(&p).expect("model").rest();
    let (mut tau, mut periods, mut unsettled) = (0.0, 0usize, 0usize);
    let mut amplitudes = Vec::new();
    for &a5 in &spec.values {
        let mut q = p;
        q.alpha5 = a5;
        let model = CantileverModel::new(&q).expect("model");
        let mut integ = build(&model, opts.clone(), tau, &state).expect("integrator");
        let mut last: Option<Vec<f64>> = None;
        let mut settled = false;
        for _ in 0..MAX_WINDOWS {
            let o = observe(integ.as_mut(), &window).expect("window");
            periods += WINDOW * q.common_periods() as usize;
            let a: Vec<f64> = o.components.iter().map(|c| c.amplitude).collect();
            let free: Vec<f64> = o.components.iter().map(|c| c.free_amplitude).collect();
            if let Some(prev) = &last {
                if a.iter()
                    .zip(prev)
                    .zip(&free)
                    .all(|((x, y), f)| (x - y).abs() < 1e-6 * f)
                {
                    settled = true;
                    last = Some(a);
                    break;
                }
            }
            last = Some(a);
        }
        unsettled += usize::from(!settled);
        amplitudes.push(last.expect("one window"));
        tau = integ.tau();
        state = integ.state().clone();
    }
    let t_time = t.elapsed().as_secs_f64();
    let worst = exact
        .first
        .iter()
        .zip(&amplitudes)
        .flat_map(|(e, a)| {
            e.observables
                .components
                .iter()
                .zip(a)
                .map(|(c, x)| (c.amplitude - x).abs() / c.free_amplitude)
        })
        .fold(0.0, f64::max);
    println!(
        "{{\"values\": {}, \"exact_s\": {t_exact:.4}, \"time_domain_s\": {t_time:.3}, \
         \"ratio\": {:.0}, \"periods\": {periods}, \"unsettled\": {unsettled}, \
         \"amplitude_difference\": {worst:.1e}}}",
        exact.first.len(),
        t_time / t_exact,
    );
}

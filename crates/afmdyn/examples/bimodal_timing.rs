//! Cost of a bimodal approach curve: the exact periodic orbits of the common period
//! ([`afmdyn::analysis::stepped::stepped_sweep`] on a multifrequency drive: both sweeps, 200
//! orbits, no branches) against the time-domain way of VEDA-like simulators, the library's
//! time average ([`afmdyn::analysis::stepped::average`]: at each z_c the motion integrated on
//! from the previous value's end state, each component demodulated over Hann² windows until
//! two successive windows agree to its tolerance of each free amplitude, then measured over a
//! longer window) — over the 100 z_c values of the default range, on
//! `examples/probe-bimodal.toml`:
//!
//! ```sh
//! cargo run --release -p afmdyn --example bimodal_timing
//! ```
//!
//! Prints one line of JSON: seconds of each, their ratio, the drive periods the time average
//! integrated, its settling window, the points that did not settle, the points whose
//! difference from the orbit exceeds their own error estimate (plus the orbits' tolerance,
//! 1e-6 of the free amplitude), and the largest difference of the components' amplitudes
//! between the two, relative to their free amplitudes.

use afmdyn::analysis::approach::{approach_spec, default_range};
use afmdyn::analysis::stepped::average::AverageOptions;
use afmdyn::analysis::stepped::{stepped_sweep, Spacing};
use afmdyn::probe::Probe;
use afmdyn::CantileverModel;
use std::path::Path;
use std::time::Instant;

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

    let opts = AverageOptions::for_model(&CantileverModel::new(&p).expect("model"));
    spec.average = Some(opts);
    let t = Instant::now();
    let averaged = stepped_sweep(&spec).expect("time average");
    let t_time = t.elapsed().as_secs_f64();

    let points = || averaged.first.iter().chain(&averaged.second);
    let estimates = || points().filter_map(|q| q.average.as_ref());
    let periods: usize = estimates().map(|e| e.periods).sum();
    let unsettled = estimates().filter(|e| !e.settled).count();
    // per point, per component: |ΔA| between orbit and average, the estimate, A0
    let points_rows: Vec<Vec<(f64, f64, f64)>> = exact
        .first
        .iter()
        .chain(&exact.second)
        .zip(points())
        .map(|(e, a)| {
            let est = a.average.as_ref().expect("an estimate");
            e.observables
                .components
                .iter()
                .zip(&a.observables.components)
                .zip(&est.amplitude_error)
                .map(|((c, x), err)| ((c.amplitude - x.amplitude).abs(), *err, c.free_amplitude))
                .collect()
        })
        .collect();
    let worst = points_rows
        .iter()
        .flatten()
        .map(|(d, _, a0)| d / a0)
        .fold(0.0, f64::max);
    // points whose difference exceeds their own estimate (plus the orbits' tolerance)
    let outside = points_rows
        .iter()
        .filter(|r| r.iter().any(|(d, err, a0)| *d > err + 1e-6 * a0))
        .count();
    println!(
        "{{\"values\": {}, \"exact_s\": {t_exact:.4}, \"time_domain_s\": {t_time:.3}, \
         \"ratio\": {:.0}, \"periods\": {periods}, \"window_periods\": {}, \
         \"tolerance\": {:e}, \"unsettled\": {unsettled}, \"outside_estimate\": {outside}, \
         \"amplitude_difference\": {worst:.1e}}}",
        exact.first.len(),
        t_time / t_exact,
        opts.window_periods,
        opts.tol,
    );
}

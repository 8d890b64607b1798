//! Cost of an FM-AFM curve: the exact steady states ([`afmdyn::analysis::fm`]) against the
//! time-domain loop ([`afmdyn::analysis::fm_loop`], a PLL and an amplitude controller updating
//! the drive once per cycle, integrated until settled), on the point mass of
//! `examples/probe-point-mass-dmt.toml` (Q = 400) over 100 z_c values from 2A + a0 down to A + a0 (the
//! request's default range before it followed the decay of the shift, kept for comparison):
//!
//! ```sh
//! cargo run --release -p afmdyn --example fm_timing
//! ```
//!
//! Prints one line of JSON: seconds of each, their ratio, the cycles the loop ran and the
//! largest difference of their frequency shifts relative to the largest shift.

use afmdyn::analysis::fm::LoopSpec;
use afmdyn::analysis::fm::{fm_curve, FmSpec};
use afmdyn::analysis::fm_loop::fm_loop;
use afmdyn::analysis::progress::Progress;
use afmdyn::probe::Probe;
use std::path::Path;
use std::time::Instant;

fn main() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/probe-point-mass-dmt.toml");
    let probe = Probe::load(&path).expect("example probe");
    let p = probe.params;
    let a0 = p.contact_law.distance_offset();
    let values: Vec<f64> = (0..100)
        .map(|i| p.alpha5_for_rest_distance(2.0 + a0 - i as f64 / 99.0))
        .collect();
    let spec = FmSpec::new(p, values, 1.0);
    let t = Instant::now();
    let exact = fm_curve(&spec, &Progress::new()).expect("exact");
    let t_exact = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let looped = fm_loop(
        &spec,
        &LoopSpec::new(probe.calibration.quality_factor),
        &Progress::new(),
    )
    .expect("loop");
    let t_loop = t.elapsed().as_secs_f64();
    let w0 = exact.reference.omega;
    let largest = exact
        .points
        .iter()
        .map(|q| (q.omega - w0).abs())
        .fold(0.0, f64::max);
    let worst = exact
        .points
        .iter()
        .zip(&looped)
        .map(|(e, l)| (e.omega - l.omega).abs())
        .fold(0.0, f64::max);
    println!(
        "{{\"values\": {}, \"exact_s\": {t_exact:.4}, \"loop_s\": {t_loop:.3}, \"ratio\": {:.0}, \
         \"loop_cycles\": {}, \"unsettled\": {}, \"shift_difference\": {:.1e}}}",
        exact.points.len(),
        t_loop / t_exact,
        looped.iter().map(|l| l.cycles).sum::<usize>(),
        looped.iter().filter(|l| !l.settled).count(),
        worst / largest
    );
}

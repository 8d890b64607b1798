//! Timing of the Sader–Jarvis inversion (scripts/perf-reconstruct.sh): on uniform grids of
//! 10⁴ and 10⁵ points (a van der Waals shift from 0.3 to 60 nm, A = 10 nm), the sum as it was
//! before the FFT (commit 203d73b, copied: every pair, each integrand value twice), the direct
//! sum now (`sader_jarvis_direct`, the reference and the method on uneven grids) and
//! `sader_jarvis` (the FFT), best of 3 (the two O(N²) sums: 1 run at 10⁵); the FFT's largest
//! difference from the direct sum over the largest |F|; the exact inversion
//! (`reconstruct_exact::exact_inversion`, best of 3), its correction steps and forward
//! residual. One JSON line.
//!
//! Usage: cargo run --release -p afmdyn --example reconstruct_timing

use afmdyn::analysis::progress::Progress;
use afmdyn::analysis::reconstruct::{sader_jarvis, sader_jarvis_direct, ShiftCurve};
use afmdyn::analysis::reconstruct_exact::exact_inversion;
use std::time::Instant;

fn before(curve: &ShiftCurve) -> Vec<f64> {
    let d = &curve.distance;
    let n = d.len();
    let (k, a) = (curve.spring_constant, curve.amplitude);
    let omega: Vec<f64> = curve
        .frequency_shift
        .iter()
        .map(|df| df / curve.resonance_frequency)
        .collect();
    let slope: Vec<f64> = (0..n)
        .map(|i| {
            let (lo, hi) = (i.saturating_sub(1), (i + 1).min(n - 1));
            (omega[hi] - omega[lo]) / (d[hi] - d[lo])
        })
        .collect();
    let (sa, a32) = (a.sqrt(), a.powf(1.5));
    let pi_sqrt = std::f64::consts::PI.sqrt();
    let mut force = vec![0.0; n];
    for j in 0..n - 1 {
        let z = d[j];
        let step = d[j + 1] - z;
        let first = omega[j] * step + sa / (4.0 * pi_sqrt) * omega[j] * step.sqrt()
            - std::f64::consts::SQRT_2 * a32 * slope[j] * step.sqrt();
        let integrand = |i: usize| {
            let s = d[i] - z;
            (1.0 + sa / (8.0 * (std::f64::consts::PI * s).sqrt())) * omega[i]
                - a32 / (2.0 * s).sqrt() * slope[i]
        };
        let rest: f64 = (j + 1..n - 1)
            .map(|i| 0.5 * (integrand(i) + integrand(i + 1)) * (d[i + 1] - d[i]))
            .sum();
        force[j] = 2.0 * k * (first + rest);
    }
    force
}

fn best<T>(runs: usize, f: impl Fn() -> T) -> (f64, T) {
    let mut out = None;
    let mut t = f64::INFINITY;
    for _ in 0..runs {
        let t0 = Instant::now();
        let r = f();
        t = t.min(t0.elapsed().as_secs_f64());
        out = Some(r);
    }
    (t, out.expect("a run"))
}

fn main() {
    let mut rows = Vec::new();
    for n in [10_000usize, 100_000] {
        let (lo, hi) = (3e-10, 6e-8);
        let h = (hi - lo) / (n - 1) as f64;
        let distance: Vec<f64> = (0..n).map(|i| lo + i as f64 * h).collect();
        // the large-amplitude shift of −HR/(6d²): Δf ∝ −d^{-3/2}
        let frequency_shift = distance
            .iter()
            .map(|d| -83.0 * (3e-10 / d).powf(1.5))
            .collect();
        let curve = ShiftCurve {
            distance,
            frequency_shift,
            spring_constant: 40.0,
            resonance_frequency: 300e3,
            amplitude: 1e-8,
        };
        let runs = if n > 10_000 { 1 } else { 3 };
        let (t_before, f_before) = best(runs, || before(&curve));
        let (t_direct, direct) = best(runs, || {
            sader_jarvis_direct(&curve, &Progress::new()).expect("direct")
        });
        let (t_fft, fft) = best(3, || sader_jarvis(&curve, &Progress::new()).expect("fft"));
        let scale = direct.force.iter().fold(0.0f64, |m, f| m.max(f.abs()));
        let diff = fft
            .force
            .iter()
            .zip(&direct.force)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
            / scale;
        assert_eq!(f_before[..n - 1], direct.force[..n - 1]);
        let (t_exact, exact) = best(3, || {
            exact_inversion(&curve, &Progress::new()).expect("exact")
        });
        let record = exact.exact.expect("the exact inversion's record");
        rows.push(format!(
            "{{\"points\": {n}, \"before_s\": {t_before:.4}, \"direct_s\": {t_direct:.4}, \
             \"fft_s\": {t_fft:.5}, \"difference\": {diff:.2e}, \"exact_s\": {t_exact:.4}, \
             \"exact_iterations\": {}, \"exact_residual\": {:.2e}}}",
            record.iterations, record.forward_residual
        ));
    }
    println!("[{}]", rows.join(", "));
}

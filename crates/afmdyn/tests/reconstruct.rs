//! The Sader–Jarvis inversion's two sums (`analysis::reconstruct`): the FFT on a uniform grid
//! gives the direct O(N²) sum's force (the reference, term by term as the module doc writes
//! it), to 1e-12 of the largest |F| on an exactly even grid and on grids written as
//! d0 + i h in floating point; the direct sum is the one it always was (the code before the FFT,
//! copied here, bit for bit); the size limits are checked before the run, naming `distance`;
//! a cancelled run stops with `Cancelled`. The exact inversion (`analysis::reconstruct_exact`,
//! issue 62 §3) on the same round trip: its forward relation is Giessibl's, it removes
//! Sader–Jarvis's few per cent at intermediate amplitudes, and on noisy data it is measured
//! against Sader–Jarvis.

use afmdyn::analysis::progress::Progress;
use afmdyn::analysis::reconstruct::{
    giessibl_shift, sader_jarvis, sader_jarvis_direct, uniform_spacing, Method, ShiftCurve,
    GIESSIBL_NODES, MAX_DIRECT_POINTS, MAX_UNIFORM_POINTS, NEAR_FIELD, UNIFORM_TOLERANCE,
};
use afmdyn::error::SimError;

const K: f64 = 40.0;
const F0: f64 = 300e3;
const HR: f64 = 1e-19 * 1e-8;

fn vdw(d: f64) -> f64 {
    -HR / (6.0 * d * d)
}

/// The shift of the van der Waals force on `distance` at amplitude `a` (Giessibl's relation).
fn curve(distance: Vec<f64>, a: f64) -> ShiftCurve {
    let frequency_shift = distance
        .iter()
        .map(|&d| giessibl_shift(&vdw, d, K, F0, a, GIESSIBL_NODES))
        .collect();
    ShiftCurve {
        distance,
        frequency_shift,
        spring_constant: K,
        resonance_frequency: F0,
        amplitude: a,
    }
}

/// The largest |difference| over the largest |F| of the reference.
fn relative_difference(got: &[f64], want: &[f64]) -> f64 {
    let scale = want.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    got.iter()
        .zip(want)
        .fold(0.0f64, |m, (g, w)| m.max((g - w).abs()))
        / scale
}

/// The direct sum as it was before the FFT (commit 203d73b), verbatim: the reference of the
/// reference.
fn sader_jarvis_before(curve: &ShiftCurve) -> Vec<f64> {
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

/// The direct sum is the code before the FFT, bit for bit (each integrand value is now
/// computed once instead of twice), on a log-spaced grid.
#[test]
fn the_direct_sum_is_the_sum_it_was() {
    let n = 1500;
    let d: Vec<f64> = (0..n)
        .map(|i| 3e-10 * 1000f64.powf(i as f64 / (n - 1) as f64))
        .collect();
    for a in [1e-10, 1e-8] {
        let c = curve(d.clone(), a);
        assert_eq!(c.method().unwrap(), Method::Direct);
        let r = sader_jarvis_direct(&c, &Progress::new()).unwrap();
        assert_eq!(r.force, sader_jarvis_before(&c), "A = {a}");
    }
}

/// On an exactly even grid (d = (20 + i) 2⁻³⁶ m: 0.29 nm to 0.29 µm in 20 000 points, every
/// difference exact), the FFT gives the direct sum to 1e-12 of the largest |F| at amplitudes
/// from 0.1 to 10 nm (measured: a few 1e-15), the potential likewise.
#[test]
fn the_fft_equals_the_direct_sum_on_an_even_grid() {
    let n = 20_000;
    let h = 2f64.powi(-36);
    let d: Vec<f64> = (0..n).map(|i| (20 + i) as f64 * h).collect();
    assert_eq!(uniform_spacing(&d), Some(h));
    for a in [1e-10, 1e-9, 1e-8] {
        let c = curve(d.clone(), a);
        assert_eq!(c.method().unwrap(), Method::Fft { h });
        let fft = sader_jarvis(&c, &Progress::new()).unwrap();
        let direct = sader_jarvis_direct(&c, &Progress::new()).unwrap();
        let (ef, eu) = (
            relative_difference(&fft.force, &direct.force),
            relative_difference(&fft.potential, &direct.potential),
        );
        eprintln!("even grid, A = {a}: force {ef:.2e}, potential {eu:.2e}");
        assert!(ef < 1e-12, "A = {a}: {ef}");
        assert!(eu < 1e-12, "A = {a}: {eu}");
        assert_eq!(fft.force[n - 1], 0.0);
    }
}

/// On grids written as d0 + i h in floating point (every distance off its even place by
/// round-off, ~1e-16 d_max), decreasing or not, of odd and even sizes, and with fewer points
/// than the near field: the FFT gives the direct sum to 1e-12 of the largest |F|.
#[test]
fn the_fft_equals_the_direct_sum_on_a_computed_grid() {
    for (n, lo, hi) in [
        (30_001, 3e-10, 3e-7),
        (4096, 1e-10, 2e-8),
        (777, 5e-10, 6e-8),
        (NEAR_FIELD + 1, 1e-9, 1e-8),
        (5, 1e-9, 1e-8),
        (3, 1e-9, 1e-8),
    ] {
        let step = (hi - lo) / (n - 1) as f64;
        let d: Vec<f64> = (0..n).map(|i| lo + i as f64 * step).collect();
        let c = curve(d, 1e-9);
        assert!(matches!(c.method().unwrap(), Method::Fft { .. }), "{n}");
        let fft = sader_jarvis(&c, &Progress::new()).unwrap();
        let direct = sader_jarvis_direct(&c, &Progress::new()).unwrap();
        let e = relative_difference(&fft.force, &direct.force);
        eprintln!("computed grid, {n} points: {e:.2e}");
        assert!(e < 1e-12, "{n} points: {e}");
    }
}

/// A grid off its even places by more than the tolerance is summed directly; one within it by
/// FFT, which then differs from the direct sum by about the unevenness over the near field.
#[test]
fn the_uniformity_criterion() {
    let n = 2000;
    let h = 1e-11;
    let even: Vec<f64> = (0..n).map(|i| 3e-10 + i as f64 * h).collect();
    let moved = |by: f64| {
        let mut d = even.clone();
        d[n / 2] += by * h;
        d
    };
    assert!(uniform_spacing(&moved(0.5 * UNIFORM_TOLERANCE)).is_some());
    assert!(uniform_spacing(&moved(3.0 * UNIFORM_TOLERANCE)).is_none());
    assert_eq!(curve(moved(1e-3), 1e-9).method().unwrap(), Method::Direct);
    let c = curve(moved(0.9 * UNIFORM_TOLERANCE), 1e-9);
    assert!(matches!(c.method().unwrap(), Method::Fft { .. }));
    let e = relative_difference(
        &sader_jarvis(&c, &Progress::new()).unwrap().force,
        &sader_jarvis_direct(&c, &Progress::new()).unwrap().force,
    );
    assert!(e < 1e-12, "{e}");
}

/// The size limits, checked before the run, name `distance`, the size and the limit.
#[test]
fn the_size_limits_are_checked_before_the_run() {
    let log_grid = |n: usize| -> Vec<f64> {
        (0..n)
            .map(|i| 3e-10 * 1000f64.powf(i as f64 / (n - 1) as f64))
            .collect()
    };
    let flat = |distance: Vec<f64>| ShiftCurve {
        frequency_shift: vec![-1.0; distance.len()],
        distance,
        spring_constant: K,
        resonance_frequency: F0,
        amplitude: 1e-9,
    };
    assert_eq!(
        flat(log_grid(MAX_DIRECT_POINTS)).method().unwrap(),
        Method::Direct
    );
    let e = sader_jarvis(&flat(log_grid(MAX_DIRECT_POINTS + 1)), &Progress::new())
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with(&format!("distance = {} values", MAX_DIRECT_POINTS + 1))
            && e.contains(&format!("at most {MAX_DIRECT_POINTS} values"))
            && e.contains("resample"),
        "{e}"
    );
    let even = |n: usize| flat((0..n).map(|i| 1e-9 + i as f64 * 1e-12).collect());
    assert!(matches!(
        even(MAX_UNIFORM_POINTS).method().unwrap(),
        Method::Fft { .. }
    ));
    let e = even(MAX_UNIFORM_POINTS + 1)
        .method()
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with(&format!("distance = {} values", MAX_UNIFORM_POINTS + 1))
            && e.contains(&format!("at most {MAX_UNIFORM_POINTS} values")),
        "{e}"
    );
}

/// Both sums count the points in the progress and stop with `Cancelled` once it is cancelled
/// (the check is inside the loop: its first chunk).
#[test]
fn a_cancelled_run_stops() {
    let n = 5000;
    let even: Vec<f64> = (0..n).map(|i| 3e-10 + i as f64 * 1e-11).collect();
    let log: Vec<f64> = (0..n)
        .map(|i| 3e-10 * 1000f64.powf(i as f64 / (n - 1) as f64))
        .collect();
    for d in [even, log] {
        let c = curve(d, 1e-9);
        let p = Progress::new();
        sader_jarvis(&c, &p).unwrap();
        assert_eq!((p.done(), p.total()), (n, Some(n)));
        let p = Progress::new();
        p.cancel();
        assert!(matches!(sader_jarvis(&c, &p), Err(SimError::Cancelled)));
        assert!(matches!(
            sader_jarvis_direct(&c, &p),
            Err(SimError::Cancelled)
        ));
    }
}

// The exact inversion of the first-order FM relation (`analysis::reconstruct_exact`, issue 62
// §3) against the same van der Waals round trip: its forward relation against Giessibl's
// quadrature, its accuracy where Sader–Jarvis is off by a few per cent, noisy data.

use afmdyn::analysis::reconstruct_exact::{
    exact_inversion, forward_shift, EXACT_MAX_ITERATIONS, EXACT_TOLERANCE,
};

/// `n` evenly spaced distances on [lo, hi].
fn even(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64)
        .collect()
}

/// The largest relative force error over the distances with A/d in [lo, hi].
fn worst(c: &ShiftCurve, force: &[f64], (lo, hi): (f64, f64)) -> f64 {
    c.distance
        .iter()
        .zip(force)
        .filter(|(&d, _)| (lo..=hi).contains(&(c.amplitude / d)))
        .map(|(&d, f)| (f / vdw(d) - 1.0).abs())
        .fold(0.0, f64::max)
}

/// The round trip at A/d ≈ 0.4–1 (A = 1 nm, d = 1–2.5 nm; 0.5 nm, d = 0.5–1.25 nm) on an even
/// grid of 0.3–300 nm (10⁵ points, h = 3 pm): Sader–Jarvis is off by a few per cent there (its
/// formula's own error at intermediate amplitudes, Welker et al. 2012; measured here, 2.2 %
/// at both amplitudes), the exact inversion within 0.5 % (measured: 2·10⁻⁵ and 7·10⁻⁵) — what is left is the force beyond the data, taken
/// as 0 by both inversions ((d/300 nm)² = 7·10⁻⁵ of F; on 0.3–30 nm it is 0.7 % at 2.5 nm)
/// and the piecewise-linear force's interpolation error, 0.75 (h/d)² ≈ 10⁻⁵ — and its forward
/// residual a hundredth of Sader–Jarvis's (or at round-off).
#[test]
fn the_exact_inversion_removes_sader_jarvis_error_at_intermediate_amplitudes() {
    for a in [0.5e-9, 1e-9] {
        let c = curve(even(0.3e-9, 300e-9, 100_000), a);
        let sj = sader_jarvis(&c, &Progress::new()).unwrap();
        let exact = exact_inversion(&c, &Progress::new()).unwrap();
        let record = exact.exact.unwrap();
        let band = (0.4, 1.0);
        let (e_sj, e_exact) = (worst(&c, &sj.force, band), worst(&c, &exact.force, band));
        eprintln!("A = {a}: SJ {e_sj}, exact {e_exact}, {record:?}");
        // Sader–Jarvis's error, measured here (not assumed): a few per cent
        assert!(e_sj > 0.02, "A = {a}: SJ off by {e_sj}");
        assert!(e_exact < 0.005, "A = {a}: exact off by {e_exact}");
        assert!(e_exact < e_sj / 5.0, "A = {a}: exact {e_exact}, SJ {e_sj}");
        // the forward residual a hundred times below Sader–Jarvis's, or at round-off
        assert!(
            record.forward_residual < 0.01 * record.sader_jarvis_residual
                || record.forward_residual <= EXACT_TOLERANCE,
            "{record:?}"
        );
        assert!(record.converged == (record.forward_residual <= EXACT_TOLERANCE));
        assert!(record.iterations <= EXACT_MAX_ITERATIONS);
    }
}

/// The discrete forward relation of the piecewise-linear force against Giessibl's quadrature
/// of the exact force: the same shift within the interpolation error (10⁻⁴ here), on the even
/// grid (FFT) and on a log-spaced one (the rows' weights).
#[test]
fn the_forward_relation_is_giessibls() {
    let log: Vec<f64> = (0..3000)
        .map(|i| 0.3e-9 * 100f64.powf(i as f64 / 2999.0))
        .collect();
    for distance in [even(0.3e-9, 30e-9, 10_000), log] {
        for a in [0.1e-9, 1e-9, 10e-9] {
            let c = curve(distance.clone(), a);
            let force: Vec<f64> = c.distance.iter().map(|&d| vdw(d)).collect();
            let got = forward_shift(&c, &force).unwrap();
            let scale = c.frequency_shift[0].abs();
            // rows whose cycle ends within the data (beyond, the force is cut at its end)
            let end = c.distance[c.distance.len() - 1] - 2.0 * a;
            let off = c
                .distance
                .iter()
                .zip(got.iter().zip(&c.frequency_shift))
                .filter(|(&d, _)| d < end)
                .map(|(_, (g, w))| (g - w).abs() / scale)
                .fold(0.0, f64::max);
            eprintln!("A = {a}: {off}");
            assert!(off < 1e-3, "A = {a}: {off}");
        }
    }
}

/// Noisy data: the exact inversion and Sader–Jarvis of the same noisy curve (uniform noise of
/// 10⁻⁴, 10⁻³ and 10⁻² of the largest |Δf|), their largest errors against the force printed —
/// the measurement behind the default of `inversion` (Sader–Jarvis): the exact inversion's
/// was 1.06–2.8 times Sader–Jarvis's. Asserted: it stays within 4 times.
#[test]
fn noisy_data_measured() {
    let a = 1e-9;
    let clean = curve(even(0.3e-9, 30e-9, 2_000), a);
    let scale = clean.frequency_shift[0].abs();
    // a deterministic pseudo-random sequence (xorshift), uniform on ±√3 σ
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut noise = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state as f64 / u64::MAX as f64 * 2.0 - 1.0) * 3f64.sqrt()
    };
    for sigma in [1e-4, 1e-3, 1e-2] {
        let noisy = ShiftCurve {
            frequency_shift: clean
                .frequency_shift
                .iter()
                .map(|f| f + sigma * scale * noise())
                .collect(),
            ..clean.clone()
        };
        let sj = sader_jarvis(&noisy, &Progress::new()).unwrap();
        let exact = exact_inversion(&noisy, &Progress::new()).unwrap();
        let record = exact.exact.unwrap();
        for band in [(0.4, 1.0), (0.1, 3.0)] {
            let (e_sj, e_exact) = (
                worst(&noisy, &sj.force, band),
                worst(&noisy, &exact.force, band),
            );
            eprintln!("sigma {sigma} band {band:?}: SJ {e_sj}, exact {e_exact}, {record:?}");
            assert!(
                e_exact < 4.0 * e_sj,
                "sigma {sigma}: exact {e_exact}, SJ {e_sj}"
            );
        }
    }
}

/// Issue 77 item 4: a frequency-shift curve's distances written in nm, or its shifts in kHz,
/// are named with their likely unit; the curve in SI has no such warning.
#[test]
fn unit_slips_in_a_shift_curve_are_named() {
    use afmdyn::request::reconstruct::ReconstructRequest;
    // from 3 nm: a shift of tens of Hz, which in kHz reads as below any a lever measures
    let distance: Vec<f64> = (0..200).map(|i| 3e-9 + 0.05e-9 * i as f64).collect();
    let c = curve(distance, 1e-9);
    let request = |d: &[f64], s: &[f64]| ReconstructRequest {
        distance: Some(d.to_vec()),
        frequency_shift: s.to_vec(),
        spring_constant: K,
        resonance_frequency: F0,
        amplitude: 1e-9,
        ..ReconstructRequest::default()
    };
    let slips = |r: ReconstructRequest| -> Vec<String> {
        r.warnings()
            .into_iter()
            .filter(|w| w.contains("written in"))
            .collect()
    };
    assert!(slips(request(&c.distance, &c.frequency_shift)).is_empty());
    let nm: Vec<f64> = c.distance.iter().map(|d| d * 1e9).collect();
    let w = slips(request(&nm, &c.frequency_shift));
    assert!(
        w.len() == 1 && w[0].starts_with("distance: ") && w[0].contains("written in nm?"),
        "{w:?}"
    );
    let khz: Vec<f64> = c.frequency_shift.iter().map(|f| f / 1e3).collect();
    let largest = khz.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    let w = slips(request(&c.distance, &khz));
    assert!(
        w.len() == 1 && w[0].starts_with("frequency_shift: ") && w[0].contains("in kHz?"),
        "{w:?} (largest {largest})"
    );
}

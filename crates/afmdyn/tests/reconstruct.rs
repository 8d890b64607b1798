//! The Sader–Jarvis inversion's two sums (`analysis::reconstruct`): the FFT on a uniform grid
//! gives the direct O(N²) sum's force (the reference, term by term as the module doc writes
//! it), to 1e-12 of the largest |F| on an exactly even grid and on grids written as
//! d0 + i h in floating point; the direct sum is the one it always was (the code before the FFT,
//! copied here, bit for bit); the size limits are checked before the run, naming `distance`;
//! a cancelled run stops with `Cancelled`.

use afmdyn::analysis::progress::Progress;
use afmdyn::analysis::reconstruct::{
    giessibl_shift, sader_jarvis, sader_jarvis_direct, sader_jarvis_with, uniform_spacing, Method,
    ShiftCurve, GIESSIBL_NODES, MAX_DIRECT_POINTS, MAX_UNIFORM_POINTS, NEAR_FIELD,
    UNIFORM_TOLERANCE,
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
        let fft = sader_jarvis(&c).unwrap();
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
        let fft = sader_jarvis(&c).unwrap();
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
        &sader_jarvis(&c).unwrap().force,
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
    let e = sader_jarvis(&flat(log_grid(MAX_DIRECT_POINTS + 1)))
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
        sader_jarvis_with(&c, &p).unwrap();
        assert_eq!((p.done(), p.total()), (n, Some(n)));
        let p = Progress::new();
        p.cancel();
        assert!(matches!(
            sader_jarvis_with(&c, &p),
            Err(SimError::Cancelled)
        ));
        assert!(matches!(
            sader_jarvis_direct(&c, &p),
            Err(SimError::Cancelled)
        ));
    }
}

//! The one-sided amplitude spectrum of a uniformly sampled time series (the `spectrum.csv` of
//! `afmdyn simulate` and the `spectrum` of Python's `simulate`), by the discrete Fourier
//! transform (rustfft): for L samples x_j with the mean removed, X_k = Σ_j x_j e^{−2πijk/L},
//! the amplitude of the harmonic at f_k = k Δf (Δf = 2π/(L Δτ), in the units of Ω) is
//! 2|X_k|/L, k = 0 … L/2 — a sinusoid A sin(f_k τ) on the grid gives A at f_k (Oppenheim &
//! Schafer, *Discrete-Time Signal Processing*, 3rd ed., §8.1).

/// Samples of the end of a run the spectrum is taken over by default (2²⁰).
pub(crate) const SPECTRUM_SAMPLES: usize = 1 << 20;

/// The amplitude spectrum of `x` sampled `samples_per_period` times per drive period 2π/Ω:
/// pairs (frequency in the units of Ω, amplitude in the units of x), `[L/2 + 1]` for
/// L = `x.len() − 1` (the last sample, which closes the last period, is left out so that L
/// samples span whole periods). Empty for fewer than 5 samples.
pub(crate) fn amplitude_spectrum(
    x: &[f64],
    samples_per_period: usize,
    omega: f64,
) -> Vec<(f64, f64)> {
    use rustfft::{num_complex::Complex, FftPlanner};
    let len = x.len().saturating_sub(1);
    if len < 4 || samples_per_period == 0 {
        return vec![];
    }
    let mean = x[..len].iter().sum::<f64>() / len as f64;
    let mut buf: Vec<Complex<f64>> = x[..len]
        .iter()
        .map(|v| Complex::new(v - mean, 0.0))
        .collect();
    FftPlanner::new().plan_fft_forward(len).process(&mut buf);
    let dt = std::f64::consts::TAU / omega / samples_per_period as f64;
    let df = std::f64::consts::TAU / (len as f64 * dt);
    (0..=len / 2)
        .map(|k| (k as f64 * df, 2.0 * buf[k].norm() / len as f64))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sum of sinusoids on the harmonics of Ω gives their amplitudes at their frequencies
    /// and nothing elsewhere (the closed form of the DFT of a harmonic on whole periods), the
    /// mean is removed.
    #[test]
    fn harmonics_have_their_amplitudes() {
        let (omega, spp, periods) = (2.6, 64, 8);
        let n = spp * periods + 1;
        let x: Vec<f64> = (0..n)
            .map(|j| {
                let tau = j as f64 * std::f64::consts::TAU / omega / spp as f64;
                0.7 + 1.5 * (omega * tau).sin() + 0.25 * (3.0 * omega * tau + 0.4).cos()
            })
            .collect();
        let s = amplitude_spectrum(&x, spp, omega);
        assert_eq!(s.len(), spp * periods / 2 + 1);
        for &(f, a) in &s {
            let expected = if (f - omega).abs() < 1e-9 {
                1.5
            } else if (f - 3.0 * omega).abs() < 1e-9 {
                0.25
            } else {
                0.0
            };
            assert!((a - expected).abs() < 1e-12, "f = {f}: {a} vs {expected}");
        }
        assert!(amplitude_spectrum(&x[..4], spp, omega).is_empty());
    }
}

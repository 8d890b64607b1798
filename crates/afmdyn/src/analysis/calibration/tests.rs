//! The calibration against closed forms: the harmonic oscillator's spectrum (Hutter &
//! Bechhoefer 1993) fitted back, noise-free and with the scatter of an averaged spectrum, for Q
//! from 2 (water) to 20 000 (vacuum); the model's own beam spectrum fitted to its static
//! stiffness through the optical lever's factors; the InvOLS of a written contact slope.

use super::*;
use crate::analysis::thermal::{thermal_spectrum, ModelUnits};
use crate::params::Params;
use rand::{RngExt, SeedableRng};
use std::f64::consts::PI;

/// The point-mass mode of k (N/m), f₀ (Hz) and Q: its correction factors are 1.
fn sho_mode(k: f64, f0: f64, q: f64) -> ThermalMode {
    ThermalMode {
        mode: 1,
        frequency: f0,
        quality_factor: Some(q),
        effective_spring_constant: k,
        mean_square_deflection: BOLTZMANN * 295.0 / k,
        mean_square_apparent_deflection: BOLTZMANN * 295.0 / k,
        deflection_factor: 1.0,
        optical_lever_factor: 1.0,
    }
}

/// The oscillator's one-sided PSD 2k_BT/(π k f₀ Q) / ((1 − r²)² + r²/Q²), r = f/f₀ (Hutter &
/// Bechhoefer 1993), at T = 295 K, on the white `floor`.
fn sho(k: f64, f0: f64, q: f64, floor: f64) -> impl Fn(f64) -> f64 {
    let p = 2.0 * BOLTZMANN * 295.0 / (PI * k * f0 * q);
    move |f| {
        let r = f / f0;
        p / ((1.0 - r * r).powi(2) + r * r / (q * q)) + floor
    }
}

/// `n` frequencies evenly spaced over [lo, hi].
fn grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64)
        .collect()
}

/// The calibration of a one-mode spectrum `s` at `f`.
fn one(f: &[f64], s: &[f64], m: ThermalMode) -> ModeCalibration {
    let c = calibrate(
        (f, s),
        &[m],
        &[],
        (Signal::Deflection, 295.0),
        &Progress::new(),
    )
    .unwrap();
    c.modes[0].clone()
}

/// Noise-free, the oscillator's own spectrum (on a floor of 1e-3 of its peak) gives its k, f₀ and Q back to 1e-6, for Q = 2 (a
/// soft lever in water), 400 (air) and 20 000 (vacuum, on a grid fine about the peak).
#[test]
fn the_oscillators_spectrum_gives_its_spring_constant_back() {
    for (k, f0, q, f) in [
        (0.1, 10e3, 2.0, grid(100.0, 60e3, 4000)),
        (40.0, 300e3, 400.0, grid(200e3, 400e3, 20_000)),
        (2.0, 70e3, 20_000.0, grid(69.5e3, 70.5e3, 20_000)),
    ] {
        let floor = 1e-3 * sho(k, f0, q, 0.0)(f0);
        let s: Vec<f64> = f.iter().map(|&x| sho(k, f0, q, floor)(x)).collect();
        let c = one(&f, &s, sho_mode(k * 1.2, f0 * 1.1, q / 3.0));
        let rel = |a: f64, b: f64| (a / b - 1.0).abs();
        assert!(
            rel(c.spring_constant_thermal.value, k) < 1e-6,
            "Q {q}: {c:?}"
        );
        assert!(rel(c.frequency.value, f0) < 1e-6, "Q {q}: {c:?}");
        assert!(rel(c.quality_factor.value, q) < 1e-6, "Q {q}: {c:?}");
        assert!(c.warnings.is_empty(), "{:?}", c.warnings);
    }
}

/// An averaged spectrum (each bin the mean of 32 exponentially distributed periodograms, a
/// fixed seed): k lies within 4 of its standard errors of the truth, and the standard error is
/// the scatter's: 200 spectra give k's spread within 25 % of the mean standard error.
#[test]
fn an_averaged_spectrum_gives_k_within_its_standard_error() {
    let (k, f0, q) = (40.0, 300e3, 400.0);
    let f = grid(250e3, 350e3, 4000);
    let clean: Vec<f64> = f.iter().map(|&x| sho(k, f0, q, 1e-30)(x)).collect();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let mut ks = Vec::new();
    let mut ses = Vec::new();
    for _ in 0..200 {
        let s: Vec<f64> = (clean.iter())
            .map(|v| {
                v * (0..32)
                    .map(|_| -(1.0 - rng.random_range(0.0..1.0f64)).ln())
                    .sum::<f64>()
                    / 32.0
            })
            .collect();
        let c = one(&f, &s, sho_mode(k, f0, q));
        let m = c.spring_constant_thermal;
        assert!((m.value - k).abs() < 4.0 * m.standard_error, "{m:?}");
        ks.push(m.value);
        ses.push(m.standard_error);
    }
    let n = ks.len() as f64;
    let mean = ks.iter().sum::<f64>() / n;
    let spread = (ks.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let se = ses.iter().sum::<f64>() / n;
    assert!((spread / se - 1.0).abs() < 0.25, "spread {spread}, SE {se}");
    assert!((mean / k - 1.0).abs() < 3.0 * spread / n.sqrt(), "{mean}");
}

/// The model's apparent-deflection spectrum of a uniform three-mode beam (the optical lever at
/// the tip, Q₁ = 100) fitted peak by peak: each peak's static spring constant through the
/// model's optical-lever factor is the beam's k_s = 3EI/L³ within 1 % (the others' tails under a
/// peak are not white), mode 1's within 0.2 %; the effective ones are k_s/χ_x,k.
#[test]
fn the_beams_peaks_give_its_static_stiffness() {
    let p = Params {
        modes: 3,
        alpha1: 0.0,
        alpha3: 0.01,
        ..Params::default()
    };
    let one = ModelUnits {
        length_m: 1e-9,
        force_n: 1e-9,
        time_s: 1e-6,
    };
    let progress = Progress::new();
    let modes = thermal_spectrum(&p, one, 295.0, 1.0, &[], &progress).unwrap();
    let top = modes.modes[2].frequency * 1.3;
    let f = grid(top / 200_000.0, top, 200_000);
    let s = thermal_spectrum(&p, one, 295.0, 1.0, &f, &progress).unwrap();
    let c = calibrate(
        (&f, &s.apparent_deflection),
        &s.modes,
        &[],
        (Signal::ApparentDeflection, 295.0),
        &progress,
    )
    .unwrap();
    assert_eq!(c.modes.len(), 3);
    for (m, want) in c.modes.iter().zip(&s.modes) {
        let k = m.static_spring_constant_thermal.value;
        let tol = if m.mode == 1 { 2e-3 } else { 1e-2 };
        assert!(
            (k / s.spring_constant - 1.0).abs() < tol,
            "mode {}: {k}",
            m.mode
        );
        let keff = m.spring_constant_thermal.value / want.effective_spring_constant;
        assert!((keff - 1.0).abs() < tol, "mode {}: {keff}", m.mode);
    }
}

/// A force curve on a hard surface written with InvOLS 50 nm/V (0.1 V baseline, contact at
/// z = 0, saturating at 9 V) gives 50 nm/V back to 1e-9.
#[test]
fn the_contact_slope_gives_the_invols() {
    let z = grid(200e-9, -600e-9, 801);
    let d: Vec<f64> = (z.iter())
        .map(|&z| (0.1 + (-z).max(0.0) / 50e-9).min(9.0))
        .collect();
    let s = invols(&z, &d).unwrap();
    assert!((s.value / 50e-9 - 1.0).abs() < 1e-9, "{s:?}");
    assert!(s.standard_error < 1e-12 * s.value.max(1.0), "{s:?}");
    let flat = vec![0.1; z.len()];
    assert!(invols(&z, &flat).is_err());
}

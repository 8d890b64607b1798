//! The thermal spectrum against closed forms: the simple harmonic oscillator's PSD (a point-mass
//! probe of Q from 2 to 20 000), equipartition (the PSD's integral against k_B T/k_s, the tip
//! mass included), the uniform beam's static stiffness 3EI/L³ and Butt & Jaschke's correction
//! factors (0.971 and 0.817 for the first mode; each mode's from the classical mode shape,
//! written here).

use super::*;
use crate::probe::Probe;

/// A probe of examples/probe-point-mass-dmt.toml (k = 40 N/m, f₀ = 300 kHz) with Q = `q`.
fn point_mass(q: f64) -> Probe {
    let text = include_str!("../../../../../examples/probe-point-mass-dmt.toml")
        .replace("quality_factor = 400", &format!("quality_factor = {q}"));
    Probe::parse(&text, "point-mass").expect("probe")
}

fn units(p: &Probe) -> ModelUnits {
    ModelUnits {
        length_m: p.scales.length_m,
        force_n: p.scales.force_n,
        time_s: p.scales.time_s,
    }
}

/// The tip's deflection PSD of probe `p` at `t` (K) over the frequencies `g` (Hz).
fn psd(p: &Probe, t: f64) -> impl Fn(&[f64]) -> Vec<f64> + '_ {
    move |g| {
        thermal_spectrum(&p.params, units(p), t, 1.0, g, &Progress::default())
            .unwrap()
            .deflection
    }
}

/// The trapezoid rule's integral of `f` over [0, `to`] on a grid fine about `f0` (step
/// f₀/(50 Q) within 20 peak widths of it), coarse elsewhere.
fn integral(f: impl Fn(&[f64]) -> Vec<f64>, f0: f64, q: f64, to: f64) -> f64 {
    let (width, start) = (f0 / q, 1e-6 * f0);
    let (lo, hi) = ((f0 - 20.0 * width).max(start), f0 + 20.0 * width);
    let mut grid: Vec<f64> = Vec::new();
    let mut push = |a: f64, b: f64, n: usize| {
        grid.extend((0..n).map(|i| a + (b - a) * i as f64 / n as f64));
    };
    push(start, lo, 20_000);
    push(lo, hi, 2_000);
    push(hi, to, 200_000);
    grid.push(to);
    let s = f(&grid);
    (1..grid.len())
        .map(|i| 0.5 * (s[i] + s[i - 1]) * (grid[i] - grid[i - 1]))
        .sum()
}

/// A point-mass probe's PSD is the simple harmonic oscillator's, S(f) = 2k_BT/(π k f₀ Q) /
/// ((1 − r²)² + r²/Q²), r = f/f₀ (Hutter & Bechhoefer 1993), with the file's k, f₀ and Q, for
/// Q from 2 (water) to 20 000 (vacuum); its one mode carries k_B T/k; the PSD's integral is
/// k_B T/k (equipartition).
#[test]
fn a_point_mass_is_the_harmonic_oscillator() {
    let (k, f0, t) = (40.0, 300e3, 295.0);
    let kt = BOLTZMANN * t;
    for q in [2.0, 30.0, 400.0, 20_000.0] {
        let p = point_mass(q);
        let freqs: Vec<f64> = (1..=400).map(|i| f0 * i as f64 / 200.0).collect();
        let s =
            thermal_spectrum(&p.params, units(&p), t, 1.0, &freqs, &Progress::default()).unwrap();
        for (f, got) in freqs.iter().zip(&s.deflection) {
            let r = f / f0;
            let want = 2.0 * kt
                / (std::f64::consts::PI * k * f0 * q)
                / ((1.0 - r * r).powi(2) + r * r / (q * q));
            assert!(
                (got / want - 1.0).abs() < 1e-9,
                "Q {q}, f {f}: {got} vs {want}"
            );
        }
        assert_eq!(s.deflection, s.apparent_deflection);
        assert!(!s.reads_slope);
        let m = s.modes[0];
        assert!((m.frequency / f0 - 1.0).abs() < 1e-12, "{}", m.frequency);
        assert!((m.effective_spring_constant / k - 1.0).abs() < 1e-12);
        assert!((m.quality_factor.unwrap() / q - 1.0).abs() < 1e-9);
        assert!((m.mean_square_deflection / (kt / k) - 1.0).abs() < 1e-12);
        let area = integral(psd(&p, t), f0, q, 200.0 * f0);
        // the tail beyond 200 f₀: ∫ S ≈ 2k_BT/(πkf₀Q) f₀⁴/(3 f³)
        let tail = 2.0 * kt / (std::f64::consts::PI * k * f0 * q) * f0 / (3.0 * 200f64.powi(3));
        assert!(
            ((area + tail) / (kt / k) - 1.0).abs() < 2e-3,
            "Q {q}: {area}"
        );
    }
}

/// The classical clamped–free mode (cosh βξ − cos βξ − σ(sinh βξ − sin βξ), written here):
/// φ'(1)/φ(1).
fn slope_over_deflection(beta: f64) -> f64 {
    let s = (beta.cosh() + beta.cos()) / (beta.sinh() + beta.sin());
    let phi = beta.cosh() - beta.cos() - s * (beta.sinh() - beta.sin());
    let dphi = beta * (beta.sinh() + beta.sin() - s * (beta.cosh() - beta.cos()));
    dphi / phi
}

/// The uniform beam without a tip mass (α1 = 0), 20 Galerkin modes: the static stiffness is
/// 3EI/L³ (3 in the model's units); each mode's deflection factor is
/// 12/β_k⁴ (0.971 for the first) and its optical-lever factor (12/β_k⁴)((2/3)φ_k'(1)/φ_k(1))²,
/// 0.817 for the first (Butt & Jaschke 1995); the modes' factors sum to 1 but for the modes
/// beyond the 20th (Σ_{k>20} 12/β_k⁴ < 1e-5).
#[test]
fn the_uniform_beam_gives_butt_and_jaschkes_factors() {
    let p = Params {
        modes: 20,
        alpha1: 0.0,
        ..Params::default()
    };
    let one = ModelUnits {
        length_m: 1.0,
        force_n: 1.0,
        time_s: 1.0,
    };
    let s = thermal_spectrum(&p, one, 300.0, 1.0, &[], &Progress::default()).unwrap();
    assert_eq!(s.spring_constant, 3.0);
    assert!(s.reads_slope);
    for (k, m) in s.modes.iter().take(4).enumerate() {
        let beta = crate::beam::beta_root(k + 1);
        let deflection = 12.0 / beta.powi(4);
        assert!((m.deflection_factor / deflection - 1.0).abs() < 1e-9, "{k}");
        let optical = deflection * (2.0 / 3.0 * slope_over_deflection(beta)).powi(2);
        assert!(
            (m.optical_lever_factor / optical - 1.0).abs() < 1e-6,
            "{k}: {} vs {optical}",
            m.optical_lever_factor
        );
    }
    assert!((s.modes[0].deflection_factor - 0.971).abs() < 5e-4);
    assert!((s.modes[0].optical_lever_factor - 0.817).abs() < 5e-4);
    let sum: f64 = s.modes.iter().map(|m| m.deflection_factor).sum();
    assert!(sum < 1.0 && sum > 1.0 - 1e-5, "{sum}");
}

/// The beam with its tip mass (examples/probe-beam-dmt.toml, three modes, Q₁ = 20 and the
/// higher modes' by the beam's damping): the PSD's integral over frequency is the sum of the
/// modes' k_B T/k_k (Kramers–Kronig: ∫ S df = k_B T h(0), whatever the damping), within
/// 2e-3 of k_B T/k_s for the probe's static stiffness k_s (the modes beyond the third, 1.35e-3
/// without a tip mass: Σ_{k>3} 12/β_k⁴); the
/// first mode's frequency is the file's f₀.
#[test]
fn the_beams_spectrum_integrates_to_its_static_compliance() {
    let text = include_str!("../../../../../examples/probe-beam-dmt.toml")
        .replace("quality_factor = 400", "quality_factor = 20");
    let p = Probe::parse(&text, "beam").unwrap();
    let t = 295.0;
    let s = thermal_spectrum(&p.params, units(&p), t, 1.0, &[], &Progress::default()).unwrap();
    let ks = p.calibration.static_spring_constant;
    assert!(
        (s.spring_constant / ks - 1.0).abs() < 1e-9,
        "{} vs {ks}",
        s.spring_constant
    );
    assert!((s.modes[0].frequency / 300e3 - 1.0).abs() < 1e-9);
    let f0 = s.modes[0].frequency;
    let top = s.modes[2].frequency;
    // the grid fine about each mode: the first's by `integral`, the others' at f₀/1000 steps
    let area = integral(psd(&p, t), f0, 20.0, 40.0 * top);
    let want = s.mean_square_deflection;
    assert!((area / want - 1.0).abs() < 1e-3, "{area} vs {want}");
    let truncation = want / (BOLTZMANN * t / ks) - 1.0;
    assert!(truncation < 0.0 && truncation > -2e-3, "{truncation}");
}

/// The compliance of the hand-kept LU (partial pivoting, reused between frequencies) equals
/// nalgebra's complex LU solve of the same Z = K − Ω²M + iΩC, for a ten-mode beam with its
/// tip mass, below, between and above its modes (1e-10).
#[test]
fn the_kept_factorisation_is_nalgebras_solve() {
    let p = Params {
        modes: 10,
        alpha1: 0.5,
        ..Params::default()
    };
    let g = Galerkin::new(&p).unwrap();
    let m = g.region(Region::Free);
    let (tip, slope, _) = observables(&p, &g, 0.9);
    let mut lu = ComplexLu::new(10);
    for omega in [0.3, 3.4, 17.0, 60.0, 450.0, 2500.0] {
        lu.factor(&m.mass, &m.damping, &m.stiffness, omega);
        let z = DMatrix::from_fn(10, 10, |i, j| {
            Complex::new(
                m.stiffness[(i, j)] - omega * omega * m.mass[(i, j)],
                omega * m.damping[(i, j)],
            )
        });
        for c in [&tip, &slope] {
            let cc = c.map(|v| Complex::new(v, 0.0));
            let y = z.clone().lu().solve(&cc).unwrap();
            let want: Complex<f64> = cc.iter().zip(y.iter()).map(|(a, b)| a * b).sum();
            let got = lu.compliance(c);
            assert!(
                (got - want).norm() <= 1e-10 * want.norm(),
                "Ω {omega}: {got} vs {want}"
            );
        }
    }
}

/// The oscillator's share below r: the whole of it far above the peak (1 − 2/(3πQr³) to
/// leading order), 2r/(πQ) far below, and half of it at r = 1 for a sharp peak; for Q from 0.5
/// (overdamped) to 10⁵; a sharp peak's tail against its closed form.
#[test]
fn the_band_fraction_is_the_oscillators() {
    for q in [0.5, 2.0, 400.0, 1e5] {
        let far = band_fraction(Some(q), 1e3);
        assert!(
            (far - (1.0 - 2.0 / (3.0 * std::f64::consts::PI * q * 1e9))).abs() < 1e-8,
            "{q}: {far}"
        );
        let low = band_fraction(Some(q), 1e-3);
        let want = 2e-3 / (std::f64::consts::PI * q);
        assert!((low / want - 1.0).abs() < 1e-5, "{q}: {low} vs {want}");
    }
    assert!((band_fraction(Some(1e5), 1.0) - 0.5).abs() < 1e-4);
    assert_eq!(band_fraction(None, 1.0), band_fraction(Some(0.5), 1.0));
    // a sharp peak's tail above r = 1.5 is ∫ dx/(x² − 1)² = r/(2(r² − 1)) − ln((r + 1)/(r − 1))/4
    // to a relative 1/Q² (the damping term dropped)
    let (q, r) = (1e5, 1.5_f64);
    let tail = r / (2.0 * (r * r - 1.0)) - ((r + 1.0) / (r - 1.0)).ln() / 4.0;
    let want = 1.0 - tail / (std::f64::consts::FRAC_PI_2 * q);
    let got = band_fraction(Some(q), r);
    assert!((got - want).abs() < 1e-12, "{got} vs {want}");
}

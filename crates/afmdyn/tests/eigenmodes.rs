//! The eigenmode model of the bimodal AFM literature (`model = "eigenmodes"`: per-mode k_j,
//! f_j, Q_j at the tip, one tip displacement Σ z_j; Lozano & García, Phys. Rev. Lett. 100,
//! 076102 (2008); García & Proksch, Eur. Polym. J. 49, 1897 (2013)): at N = 1 it is the point
//! mass exactly; its modes are the given ones; at N = 2 with the Galerkin beam's k̃_j, f_j, Q_j
//! it follows the beam in the attractive regime (AM and FM on either mode); bad arrays are
//! refused naming the key.

use afmdyn::analysis::approach::{approach_retract, approach_spec};
use afmdyn::analysis::fm::{fm_curve, FmSpec};
use afmdyn::analysis::progress::Progress;
use afmdyn::analysis::stepped::Spacing;
use afmdyn::eigen::spectrum;

use super::common;
use afmdyn::probe::Probe;

/// The tip, sample and single-frequency drive of the checks.
fn sample() -> String {
    format!(
        "{}[drive]\nfree_amplitude = 10e-9\n",
        common::TIP_OVER_POLYSTYRENE
    )
}

fn probe(head: &str) -> Probe {
    Probe::parse(&format!("{head}{}", sample()), "test").unwrap()
}

const POINT_MASS: &str = "model = \"point-mass\"\n[cantilever]\nspring_constant = 40.0\n\
                          resonance_frequency = 300e3\nquality_factor = 400\n";
const ONE_MODE: &str = "model = \"eigenmodes\"\n[cantilever]\nspring_constant = [40.0]\n\
                        resonance_frequency = [300e3]\nquality_factor = [400]\n";
const BEAM: &str = "model = \"beam\"\nmodes = 3\n[cantilever]\nspring_constant = 40.0\n\
                    resonance_frequency = 300e3\nquality_factor = 400\n";

/// The AM approach's first-harmonic amplitudes (g₀) from z_c = `from` to `to` (g₀).
fn amplitudes(p: &Probe, from: f64, to: f64, points: usize) -> Vec<f64> {
    let spec = approach_spec(p.params, from, to, Spacing::Points(points)).unwrap();
    approach_retract(&spec)
        .unwrap()
        .first
        .iter()
        .map(|q| q.observables.amplitude)
        .collect()
}

#[test]
fn one_eigenmode_is_the_point_mass() {
    let (pm, e1) = (probe(POINT_MASS), probe(ONE_MODE));
    assert_eq!(pm.scales, e1.scales);
    let (a, b) = (amplitudes(&e1, 1.2, 0.3, 15), amplitudes(&pm, 1.2, 0.3, 15));
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() <= 1e-12, "{x} vs {y}");
    }
}

#[test]
fn the_modes_are_the_given_ones() {
    let p = probe(
        "model = \"eigenmodes\"\n[cantilever]\nspring_constant = [2.0, 80.0, 600.0]\n\
         resonance_frequency = [70e3, 440e3, 1.2e6]\nquality_factor = [150, 500, 900]\n",
    );
    assert_eq!(p.params.modes, 3);
    let (free, _) = spectrum(&p.params).unwrap();
    let damped: Vec<_> = free.eigenvalues.iter().filter(|e| e.im > 0.0).collect();
    for (j, (f, q)) in [(70e3, 150.0), (440e3, 500.0), (1.2e6, 900.0)]
        .iter()
        .enumerate()
    {
        let hz = p.scales.frequency_hz(free.omega[j]);
        assert!((hz / f - 1.0).abs() < 1e-12, "f{j}: {hz}");
        let qj = 0.5 / damped[j].zeta;
        assert!((qj / q - 1.0).abs() < 1e-9, "Q{j}: {qj}");
    }
    // each mode's stiffness at the tip
    let g = afmdyn::galerkin::Galerkin::new(&p.params).unwrap();
    for (j, k) in [2.0, 80.0, 600.0].iter().enumerate() {
        let (_, _, kt) =
            afmdyn::eigen::mode_at_tip(g.region(afmdyn::galerkin::Region::Free), g.tip(), j);
        let si = kt * p.scales.force_n / p.scales.length_m;
        assert!((si / k - 1.0).abs() < 1e-12, "k{j}: {si}");
    }
    // static: the modes' springs in series
    let series = 1.0 / (1.0 / 2.0 + 1.0 / 80.0 + 1.0 / 600.0);
    assert!((p.calibration.static_spring_constant / series - 1.0).abs() < 1e-12);
}

/// The two-mode eigenmode model with the beam's k̃_j, f_j, Q_j follows the Galerkin beam (N =
/// 3) in the attractive regime: FM on either mode within 0.5 % of the shift, the AM approach's
/// amplitude within 0.2 % of A₀ (the beam's third mode and the mode shapes' coupling through
/// the tip mass-free beam are what the two-mode model leaves out).
#[test]
fn two_eigenmodes_follow_the_beam_in_the_attractive_regime() {
    let beam = probe(BEAM);
    let eig = common::two_modes_of(&beam, &sample());
    assert_eq!(eig.params.modes, 2);
    let g0 = beam.scales.length_m;
    for mode in [1, 2] {
        let shift = |p: &Probe| -> Vec<f64> {
            let values = (0..8)
                .map(|i| {
                    p.params
                        .alpha5_for_rest_distance((14e-9 - i as f64 * 0.4e-9) / g0)
                })
                .collect();
            let spec = FmSpec {
                mode,
                ..FmSpec::new(p.params, values, 1.0)
            };
            let c = fm_curve(&spec, &Progress::new()).unwrap();
            assert!(c.unreached.is_none());
            c.points
                .iter()
                .map(|q| p.scales.frequency_hz(q.omega - c.reference.omega))
                .collect()
        };
        let (b, e) = (shift(&beam), shift(&eig));
        for (x, y) in b.iter().zip(&e) {
            assert!(
                (x - y).abs() <= 5e-3 * x.abs(),
                "mode {mode}: beam {x} Hz, eigenmodes {y} Hz"
            );
        }
    }
    let (a, b) = (
        amplitudes(&beam, 1.6, 1.1, 10),
        amplitudes(&eig, 1.6, 1.1, 10),
    );
    for (x, y) in a.iter().zip(&b) {
        assert!(
            (x - y).abs() <= 2e-3,
            "AM amplitude: beam {x}, eigenmodes {y}"
        );
    }
}

#[test]
fn bad_eigenmode_arrays_are_refused_naming_the_key() {
    for (cant, needle) in [
        (
            "spring_constant = 40.0\nresonance_frequency = [300e3]\nquality_factor = [400]",
            "spring_constant must be an array",
        ),
        (
            "spring_constant = [40.0, 1500.0]\nresonance_frequency = [300e3]\nquality_factor = [400, 2000]",
            "one of each per mode",
        ),
        (
            "spring_constant = [40.0, 1500.0]\nresonance_frequency = [300e3, 200e3]\nquality_factor = [400, 2000]",
            "must increase",
        ),
        (
            "spring_constant = [40.0, -1.0]\nresonance_frequency = [300e3, 2e6]\nquality_factor = [400, 2000]",
            "spring_constant[1]",
        ),
        (
            "spring_constant = [40.0]\nresonance_frequency = [300e3]\nquality_factor = [400]\nthickness = 4e-6",
            "unknown key [cantilever].thickness",
        ),
    ] {
        let text = format!(
            "model = \"eigenmodes\"\n[cantilever]\n{cant}\n{}",
            sample()
        );
        let e = Probe::parse(&text, "p.toml").unwrap_err().to_string();
        assert!(e.contains(needle), "{needle}: {e}");
    }
    let text = format!(
        "model = \"eigenmodes\"\nmodes = 3\n[cantilever]\nspring_constant = [40.0]\n\
         resonance_frequency = [300e3]\nquality_factor = [400]\n{}",
        sample()
    );
    let e = Probe::parse(&text, "p.toml").unwrap_err().to_string();
    assert!(e.contains("modes = 3"), "{e}");
}

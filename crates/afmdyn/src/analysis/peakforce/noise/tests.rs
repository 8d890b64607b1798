//! The tap's linear-response noise against the thermally driven tapping lever itself (the
//! stochastic step of `crate::integrate::exact::noise`: exact over a linear sample,
//! exponential Euler over a DMT one, [`simulated_tap_noise`]): the per-cycle peak force and
//! deformation of a simulated run, each the largest over the cycle's grid points.

use super::*;
use crate::analysis::peakforce::{steady_tap, PeakForceOptions};
use crate::analysis::thermal::BOLTZMANN;
use crate::integrate::exact::ThermalForce;
use crate::probe::Probe;

/// A point-mass lever of `k` (N/m; 70 kHz, Q = 20) over `sample` (a `[sample]` table's lines),
/// modulated at f₀/f_m = 10 with A_m = 20 nm.
fn probe(k: f64, sample: &str) -> Probe {
    let text = format!(
        "model = \"point-mass\"\n[cantilever]\nspring_constant = {k}\n\
         resonance_frequency = 70e3\nquality_factor = 20\n[tip]\nradius = 10e-9\n\
         [sample]\n{sample}\n[drive]\nmode = \"off-resonance\"\n\
         modulation_frequency = 7e3\nmodulation_amplitude = 20e-9\n"
    );
    Probe::parse(&text, "peakforce point mass").expect("probe")
}

/// Over a linear sample (2 N/m, 10 nm past the tip's rest) and over polystyrene (DMT, 2 nm past,
/// H = 10⁻²¹ J: the 2 N/m lever does not jump to contact, [`TapNoise::snap_in`]),
/// the chain's σ of the peak force and the deformation against the simulated lever's per-cycle
/// values over 3 000 cycles after a burn-in, at 295 K: within 4 standard errors of the simulated
/// σ (batch means over 20 batches). σ_F is 2–5 % of the peak force, where the linear response
/// holds; the grid's 2 048 points per cycle (205 per lever period) resolve the peak within
/// 10⁻³ of the contact's oscillation.
#[test]
fn the_simulated_tap_agrees() {
    for (name, k, sample) in [
        (
            "linear",
            0.4,
            "law = \"linear\"\nstiffness = 2.0\nz_c = 10e-9",
        ),
        (
            "dmt",
            2.0,
            "law = \"dmt\"\nyoungs_modulus = 4e9\npoisson_ratio = 0.33\nhamaker = 1e-21\n\
             z_c = 18e-9",
        ),
    ] {
        tap_agrees(name, &probe(k, sample));
    }
}

/// With the Hamaker constant of polystyrene in air (H = 6.6·10⁻²⁰ J, R = 10 nm) the attraction's
/// stiffness at the DMT contact, HR/(3a₀³) = 49 N/m, passes the 2 N/m lever's: the tap jumps to
/// contact and is flagged ([`TapNoise::snap_in`], the module docs' 8× case); with H = 10⁻²¹ J,
/// 0.74 N/m, it does not.
#[test]
fn a_jump_to_contact_is_flagged() {
    for (h, jumps) in [(6.6e-20, true), (1e-21, false)] {
        let probe = probe(
            2.0,
            &format!(
                "law = \"dmt\"\nyoungs_modulus = 4e9\npoisson_ratio = 0.33\nhamaker = {h}\n\
                 z_c = 18e-9"
            ),
        );
        let model = CantileverModel::new(&probe.params).unwrap();
        let tap = steady_tap(&model, &PeakForceOptions::default()).unwrap();
        let noise = tap_noise(&model, &tap.state, 1, 1e-6, IntegratorOptions::default()).unwrap();
        assert_eq!(noise.snap_in, jumps, "H = {h}");
        assert!(
            noise.peak_force > 0.0 && noise.deformation > 0.0,
            "{noise:?}"
        );
    }
}

/// `the_simulated_tap_agrees` on `probe`.
fn tap_agrees(name: &str, probe: &Probe) {
    let model = CantileverModel::new(&probe.params).unwrap();
    let kt = BOLTZMANN * 295.0 / (probe.scales.force_n * probe.scales.length_m);
    let tap = steady_tap(&model, &PeakForceOptions::default()).unwrap();
    assert_eq!(tap.period, 1, "{name}: a period-1 tap");
    let noise = tap_noise(&model, &tap.state, 1, kt, IntegratorOptions::default()).unwrap();
    assert!(!noise.snap_in, "{name}: no jump to contact");
    assert!(!noise.flat_peak, "{name}: a sharp peak");
    let force = ThermalForce::new(kt, 5);
    let run = simulated_tap_noise(&model, &tap.state, 1, force, 3000, 2048).unwrap();
    for (what, [sigma, se], predicted) in [
        ("peak force", run.peak_force, noise.peak_force),
        ("deformation", run.deformation, noise.deformation),
    ] {
        println!(
            "{name}, {what}: simulated σ {sigma:.4e} ± {se:.2e}, linear response {predicted:.4e}"
        );
        assert!(
            (sigma - predicted).abs() < 4.0 * se,
            "{name} {what}: {sigma} ± {se} vs {predicted}"
        );
    }
    println!(
        "{name}: peak force {:.4e}, σ_F {:.3e} (F̃); deformation {:.4e}, σ {:.3e} (g₀)",
        tap.channels.peak_force, noise.peak_force, tap.channels.deformation, noise.deformation
    );
}

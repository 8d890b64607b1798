//! The lock-in's linear-response noise against two independent calculations: on the free lever,
//! the thermal spectrum filtered by the lock-in (`spectral_lock_in_variance`, from the
//! fluctuation–dissipation theorem's PSD of `crate::analysis::thermal`, with no integrator); at a
//! setpoint in intermittent contact, the lock-in's output of a simulated thermally driven
//! tapping lever (the stochastic step of `crate::integrate::exact::noise`: exact over a linear
//! sample and an SLS one, exponential Euler over a DMT one); over an impacting orbit, an
//! Euler–Maruyama simulation with Newton's restitution written in the test.

use super::*;
use crate::analysis::am_loop::{demodulate_period, LockIn};
use crate::analysis::orbit_noise::{Walk, ETA};
use crate::analysis::peakforce::batch_variance;
use crate::analysis::progress::Progress;
use crate::analysis::shooting::{shoot, ShootingOptions};
use crate::analysis::thermal::{thermal_spectrum, ModelUnits, BOLTZMANN};
use crate::galerkin::Region;
use crate::integrate::exact::noise::holding_samples;
use crate::integrate::exact::{ThermalExact, ThermalForce};
use crate::integrate::{build, Integrator};
use crate::maps::StroboscopicMap;
use crate::probe::Probe;
use std::f64::consts::TAU;

/// k_B T at 295 K in the model's energy unit of `p`.
fn kt_model(p: &Probe) -> f64 {
    BOLTZMANN * 295.0 / (p.scales.force_n * p.scales.length_m)
}

/// The variances (m², and m² of A δφ) of the lock-in's amplitude and phase on the free lever
/// of `p` (`model` its model) driven to the first harmonic of phase lag `phi`, at 295 K, with
/// `samples` per period and the time constant `time_constant` (units of τ), from the thermal
/// spectrum S(f) alone: the output after period K is linear in the deflection's samples n(t_s),
/// Σ_s c_s n(t_s), with c_s = β(1 − β)^k (2/M) sin(θ_j − φ) for the amplitude (cos for A δφ) at
/// sample j of period K − k (`crate::analysis::am_loop`'s rectangle rule and first-order
/// low-pass), so Var = ∫₀^∞ S(f) |Σ_s c_s e^{2πi f t_s}|² df (R(t) = ∫₀^∞ S(f) cos 2πft df):
/// |G(f)|² |D(f)|² with G(f) = β/(1 − (1 − β)e^{−2πifT}) and D(f) = (2/M) Σ_j sin(θ_j − φ)
/// e^{2πif jT/M}, summed over 0 < f < 40 f_d on a grid of 2·10⁻⁴ f_d (which resolves G's peaks,
/// of width β/(2πT), and the lever's, of width f₀/Q for Q ≤ 500).
pub(crate) fn spectral_lock_in_variance(
    p: &Probe,
    model: &CantileverModel,
    samples: usize,
    time_constant: f64,
    phi: f64,
) -> [f64; 2] {
    let psi = model.params().drive_phase();
    spectral_component_variance(p, model, samples, time_constant, phi, (model.omega(), psi))
}

/// [`spectral_lock_in_variance`] of the lock-in at `omega_c` (per τ) with the drive's phase
/// `psi` (θ = ω_c τ + ψ) under a drive of common period T_c = qT: M = `samples` per drive period
/// T = 2π/Ω, the low-pass once per T. Read at the end of T_c, the output is Σ_k β(1 − β)^k
/// X_{K−k}, and window K − k's phases repeat every q windows, so the sum over windows is
/// Σ_{r<q} β(1 − β)^r D_r(f) / (1 − (1 − β)^q e^{−2πif qT}), D_r(f) = (2/M) Σ_j
/// sin(ω_c u_{rj} + ψ − φ) e^{2πif u_{rj}} over the samples u_{rj} = −(r + 1)T + jT/M of window
/// K − r, times measured from the end (ω_c T_c a whole number of cycles). For q = 1 it is
/// |G(f)|² |D(f)|² above.
fn spectral_component_variance(
    p: &Probe,
    model: &CantileverModel,
    samples: usize,
    time_constant: f64,
    phi: f64,
    (omega_c, psi): (f64, f64),
) -> [f64; 2] {
    let q = model.params().common_periods() as usize;
    let period = TAU / model.omega();
    let f_d = 1.0 / (period * p.scales.time_s);
    let beta = -(-period / time_constant).exp_m1();
    let df = 2e-4 * f_d;
    let f: Vec<f64> = (1..200_000).map(|i| i as f64 * df).collect();
    let units = ModelUnits {
        length_m: p.scales.length_m,
        force_n: p.scales.force_n,
        time_s: p.scales.time_s,
    };
    let s = thermal_spectrum(&p.params, units, 295.0, 1.0, &f, &Progress::default())
        .unwrap()
        .deflection;
    let decay = (1.0 - beta).powi(q as i32);
    [0, 1].map(|part| {
        f.iter()
            .zip(&s)
            .map(|(&f, &s)| {
                // rad per unit τ
                let x = TAU * f * p.scales.time_s;
                let (mut re, mut im) = (0.0, 0.0);
                for r in 0..q {
                    let w = beta * (1.0 - beta).powi(r as i32) * 2.0 / samples as f64;
                    for j in 1..=samples {
                        let u = period * (j as f64 / samples as f64 - (r + 1) as f64);
                        let theta = omega_c * u + psi - phi;
                        let c = if part == 0 { theta.sin() } else { theta.cos() };
                        re += w * c * (x * u).cos();
                        im += w * c * (x * u).sin();
                    }
                }
                let den = 1.0 + decay * decay - 2.0 * decay * (x * q as f64 * period).cos();
                s * (re * re + im * im) / den * df
            })
            .sum::<f64>()
    })
}

/// A point-mass lever (40 N/m, 300 kHz) of quality factor `q`, driven at resonance to 10 nm,
/// over a linear sample of `stiffness` (N/m) at `z_c` (m).
pub(crate) fn tapping_point_mass(q: f64, stiffness: f64, z_c: f64) -> Probe {
    point_mass_over(
        q,
        &format!("law = \"linear\"\nstiffness = {stiffness}\nz_c = {z_c}"),
    )
}

/// [`tapping_point_mass`] over the sample section `sample` (its keys).
fn point_mass_over(q: f64, sample: &str) -> Probe {
    let text = format!(
        "model = \"point-mass\"\n[cantilever]\nspring_constant = 40.0\n\
         resonance_frequency = 300e3\nquality_factor = {q}\n[tip]\nradius = 10e-9\n\
         [sample]\n{sample}\n[drive]\nfree_amplitude = 10e-9\nfrequency = 300e3\n"
    );
    Probe::parse(&text, "point mass").expect("probe")
}

/// The period-1 orbit of `model` near `guess` (Newton on the exact propagator's map).
fn orbit(model: &CantileverModel, guess: &DVector<f64>) -> DVector<f64> {
    let mut map =
        StroboscopicMap::build(model, IntegratorOptions::default(), guess, 1).expect("map");
    shoot(&mut map, guess, &ShootingOptions::default())
        .expect("orbit")
        .state
}

/// The period-1 orbit of the point mass `model` settled from rest over 400 periods.
fn settled_orbit(model: &CantileverModel) -> DVector<f64> {
    let options = IntegratorOptions::default();
    let mut integ = build(model, options, 0.0, &model.rest()).unwrap();
    crate::integrate::advance(integ.as_mut(), 400.0 * model.period()).unwrap();
    orbit(model, integ.state())
}

/// The water beam (examples/probe-water-beam.toml: three modes in water, Q₁ ≈ 2.3) over a
/// linear sample out of reach.
fn water_beam() -> Probe {
    let text = include_str!("../../../../../examples/probe-water-beam.toml");
    let (head, rest) = text.split_at(text.find("[sample]").unwrap());
    let tail = &rest[rest.find("[drive]").unwrap()..];
    let sample = "[sample]\nlaw = \"linear\"\nstiffness = 1.0\nz_c = 1e-6\n";
    Probe::parse(&format!("{head}{sample}{tail}"), "water").expect("probe")
}

/// On the free lever the chain is linear and Gaussian, so its σ_A², σ_φ² must be the thermal
/// spectrum filtered by the lock-in (`spectral_lock_in_variance`) to the quadrature errors of
/// both (the chain's trapezoid rule, 10⁻⁵; the spectral sum's grid): within 10⁻³, for the water
/// beam (three modes, Q₁ ≈ 2.3) and a point mass of Q = 400 in air, τ_L = 8T and T/4. With
/// Q ≫ 1 at resonance both are S_x(f₀)/(2(τ_c + τ_L)) (module docs), k_BT/k at τ_L → 0:
/// the point mass's within its 1/Q corrections.
#[test]
fn free_lever_matches_the_spectrum() {
    let samples = crate::analysis::am_loop::LOCK_IN_SAMPLES;
    for (name, probe) in [
        ("water beam", water_beam()),
        ("point mass Q = 400", tapping_point_mass(400.0, 1.0, 1e-6)),
    ] {
        let model = CantileverModel::new(&probe.params).unwrap();
        let z = orbit(&model, &DVector::zeros(model.dim()));
        let kt = kt_model(&probe);
        let period = model.period();
        for tl in [8.0 * period, 0.25 * period] {
            let noise = lock_in_noise(&model, &z, kt, tl, samples).unwrap();
            let mut integ = build(&model, IntegratorOptions::default(), 0.0, &z).unwrap();
            let (a, phi) = demodulate_period(integ.as_mut(), &model, samples).unwrap();
            let spectral = spectral_lock_in_variance(&probe, &model, samples, tl, phi);
            let l2 = probe.scales.length_m.powi(2);
            let chain = [noise.amplitude.powi(2) * l2, (noise.phase * a).powi(2) * l2];
            for (what, (c, s)) in ["amplitude", "phase"]
                .iter()
                .zip(chain.iter().zip(spectral))
            {
                println!(
                    "{name}, τ_L = {:.2} T, {what}: {c:.5e} m² (spectrum {s:.5e})",
                    tl / period
                );
                assert!((c / s - 1.0).abs() < 1e-3, "{name} {what}: {c} vs {s}");
            }
            if name.starts_with("point") {
                // the slow-flow closed form: σ_A² = k_BT/k · τ_c/(τ_c + τ_L), τ_c = 2Q/ω₀
                let tau_c = 2.0 * 400.0 / model.omega();
                let k = probe.calibration.spring_constant;
                let closed = BOLTZMANN * 295.0 / k * tau_c / (tau_c + tl);
                assert!(
                    (chain[0] / closed - 1.0).abs() < 0.02,
                    "{} vs {closed}",
                    chain[0]
                );
            }
        }
    }
}

/// Under a bimodal drive (examples/probe-bimodal.toml: two eigenmodes, 300 kHz and 1.875 MHz =
/// 25/4 f₁, Q = 400 and 2500, the sample out of reach) each component's lock-in, summing over
/// each drive period (6.25 cycles of the second) and low-passed once per drive period, must
/// read the thermal spectrum filtered by its own demodulation and low-pass, periodic over the
/// common period of 4 drive periods (`spectral_component_variance`): σ_A², σ_φ² within 10⁻⁶
/// (measured 2·10⁻⁸) for both components at τ_L = 8 T_c and T_c/4. The second mode's σ_A is then about √(k_BT/k₂), its
/// own equipartition (k₂ = 1571 N/m), not the first mode's: each lock-in reads its own mode.
#[test]
fn each_bimodal_lock_in_matches_the_spectrum() {
    let text = include_str!("../../../../../examples/probe-bimodal.toml");
    let (head, rest) = text.split_at(text.find("[sample]").unwrap());
    let tail = &rest[rest.find("[drive]").unwrap()..];
    let sample = "[sample]\nlaw = \"linear\"\nstiffness = 1.0\nz_c = 1e-6\n";
    let probe = Probe::parse(&format!("{head}{sample}{tail}"), "bimodal").expect("probe");
    let model = CantileverModel::new(&probe.params).unwrap();
    let q = model.params().common_periods() as usize;
    assert_eq!(q, 4);
    let z = orbit(&model, &DVector::zeros(model.dim()));
    let (kt, period) = (kt_model(&probe), model.period());
    let samples = crate::analysis::am_loop::LOCK_IN_SAMPLES;
    let references = model.params().demodulated();
    let l2 = probe.scales.length_m.powi(2);
    for tl in [8.0 * period, 0.25 * period] {
        let noise = lock_in_noise(&model, &z, kt, tl, samples).unwrap();
        let (_, harmonics) = period_chain(&model, &z, kt, tl, samples).unwrap();
        for (c, &(omega, psi)) in references.iter().enumerate() {
            let (x, y) = harmonics[c];
            let (a, phi) = (x.hypot(y), y.atan2(x));
            let s = spectral_component_variance(&probe, &model, samples, tl, phi, (omega, psi));
            let sigma = match c {
                0 => [noise.amplitude, noise.phase],
                _ => noise.further[c - 1],
            };
            let chain = [sigma[0].powi(2) * l2, (sigma[1] * a).powi(2) * l2];
            for (what, (c2, s2)) in ["amplitude", "phase"].iter().zip(chain.iter().zip(s)) {
                println!(
                    "component {}, τ_L = {:.2} T_c, {what}: {c2:.5e} m² (spectrum {s2:.5e}, {:.1e})",
                    c + 1,
                    tl / period,
                    c2 / s2 - 1.0
                );
                assert!((c2 / s2 - 1.0).abs() < 1e-6, "{c} {what}: {c2} vs {s2}");
            }
        }
        assert!(noise.further[1..].iter().flatten().all(|v| v.is_nan()));
    }
    // at τ_L = T_c/4 against τ_c ≈ 0.4 ms the second mode's σ_A is near √(k_BT/k₂)
    let noise = lock_in_noise(&model, &z, kt, 0.25 * period, samples).unwrap();
    let sigma2 = noise.further[0][0] * probe.scales.length_m;
    let equipartition = (BOLTZMANN * 295.0 / 1571.0).sqrt();
    assert!(
        (sigma2 / equipartition - 1.0).abs() < 0.02,
        "{sigma2} vs {equipartition}"
    );
}

/// In intermittent contact a second drive component of vanishing force (10⁻⁴ of the first's
/// free amplitude, at 5/2 f₁: a common period of 2 drive periods) leaves the orbit the
/// single-frequency one, so the first component's lock-in, low-passed once per common period,
/// must read the single-frequency lock-in's σ_A and σ_φ (validated against the simulated
/// thermally driven lever in `at_a_setpoint_the_simulated_lock_in_agrees`) up to the filters'
/// update intervals: within 10⁻⁴ at τ_L = 100 T (measured 3·10⁻⁶), on the Q = 100 point mass over a
/// 40 N/m linear sample at A/A₀ ≈ 0.65 (the saltations of every contact in the chain).
#[test]
fn a_vanishing_second_component_leaves_the_first_lock_in() {
    let single = tapping_point_mass(100.0, 40.0, 6e-9);
    let text = "model = \"point-mass\"\n[cantilever]\nspring_constant = 40.0\n\
         resonance_frequency = 300e3\nquality_factor = 100\n[tip]\nradius = 10e-9\n\
         [sample]\nlaw = \"linear\"\nstiffness = 40.0\nz_c = 6e-9\n\
         [drive]\nfree_amplitude = [10e-9, 1e-12]\nfrequency = [300e3, 750e3]\n";
    let double = Probe::parse(text, "two components").expect("probe");
    let sigma = |probe: &Probe| {
        let model = CantileverModel::new(&probe.params).unwrap();
        let z = settled_orbit(&model);
        let tl = 100.0 * TAU / model.omega();
        let samples = crate::analysis::am_loop::LOCK_IN_SAMPLES;
        let n = lock_in_noise(&model, &z, kt_model(probe), tl, samples).unwrap();
        (model.params().common_periods(), [n.amplitude, n.phase])
    };
    let ((q1, one), (q2, two)) = (sigma(&single), sigma(&double));
    assert_eq!((q1, q2), (1, 2));
    for (what, (a, b)) in ["amplitude", "phase"].iter().zip(one.iter().zip(two)) {
        println!("{what}: single {a:.6e}, first of two {b:.6e}");
        assert!((b / a - 1.0).abs() < 1e-4, "{what}: {a} vs {b}");
    }
}

/// At a setpoint in intermittent contact (A/A₀ ≈ 0.65, Q = 100) the chain's σ_A and σ_φ against
/// the lock-in's output of the thermally driven lever itself (the stochastic step, the
/// switchings the noise moves located on the Gaussian bridge), 40 000 periods after a burn-in,
/// τ_L = 8T: within 4 standard errors of the simulated variance (batch means over 40 batches).
/// Over a 40 N/m linear sample (the exact stochastic step), over polystyrene (DMT, the
/// exponential Euler step; examples/probe-point-mass-dmt.toml at Q = 100) and over an SLS
/// sample (20 N/m relaxed, a Maxwell arm of 40 N/m relaxing in 0.3 µs: the exact step in
/// 2N + 1 dimensions with the dashpot's own thermal force, against the chain's). The noise
/// σ ≈ 10 pm is 10⁻³ of the amplitude, where the linear response holds.
#[test]
fn at_a_setpoint_the_simulated_lock_in_agrees() {
    let text = include_str!("../../../../../examples/probe-point-mass-dmt.toml")
        .replace("quality_factor = 400", "quality_factor = 100")
        .replace("z_c = 8e-9", "z_c = 5.6e-9");
    let dmt = Probe::parse(&text, "dmt").expect("probe");
    let sls = point_mass_over(
        100.0,
        "law = \"sls\"\nstiffness = 20.0\nmaxwell_stiffness = 40.0\nrelaxation_time = 0.3e-6\n\
         z_c = 6e-9",
    );
    for probe in [tapping_point_mass(100.0, 40.0, 6e-9), dmt, sls] {
        setpoint_agrees(&probe);
    }
}

/// `at_a_setpoint_the_simulated_lock_in_agrees` on `probe`.
fn setpoint_agrees(probe: &Probe) {
    let samples = crate::analysis::am_loop::LOCK_IN_SAMPLES;
    let model = CantileverModel::new(&probe.params).unwrap();
    let z = settled_orbit(&model);
    let kt = kt_model(probe);
    let period = model.period();
    let tl = 8.0 * period;
    let noise = lock_in_noise(&model, &z, kt, tl, samples).unwrap();
    let opts = IntegratorOptions {
        steps_per_period: holding_samples(1, samples),
        ..IntegratorOptions::default()
    };
    let mut it = ThermalExact::new(&model, &opts, ThermalForce::new(kt, 11)).unwrap();
    it.reset(0.0, &z).unwrap();
    let (a_det, phi) = demodulate_period(&mut it.clone(), &model, samples).unwrap();
    let free = crate::analysis::observables::free_response(&model)
        .unwrap()
        .amplitude;
    println!("A/A0 = {:.3}", a_det / free);
    assert!(
        a_det < 0.7 * free && a_det > 0.4 * free,
        "{a_det} of {free}"
    );
    let mut lock = LockIn::new(tl, period, a_det, phi);
    let (burn, batches, per) = (400, 40, 1000);
    let mut series = [Vec::new(), Vec::new()];
    for k in 0..burn + batches * per {
        let (ak, pk) = demodulate_period(&mut it, &model, samples).unwrap();
        lock.update(ak, pk);
        let z = it.state().clone();
        it.reset(0.0, &z).unwrap();
        if k >= burn {
            series[0].push(lock.amplitude());
            series[1].push(lock.phase());
        }
    }
    // within 4 standard errors of the batch means (batches much longer than the output's
    // correlation)
    let predicted = [noise.amplitude.powi(2), noise.phase.powi(2)];
    for ((what, s), pred) in ["amplitude", "phase"].iter().zip(&series).zip(predicted) {
        let [mean, se] = batch_variance(s, per, usize::MAX);
        println!("{what}: simulated {mean:.4e} ± {se:.2e}, linear response {pred:.4e}");
        assert!(
            (mean - pred).abs() < 4.0 * se,
            "{what}: {mean} ± {se} vs {pred}"
        );
    }
}

/// Under SLS the chain walks the Maxwell arm's extension u with the lever: exactly between
/// switchings (Van Loan over the model's Jacobian, affine in each region with u), by the
/// trapezoid rule across them (`crate::analysis::orbit_noise`). A point mass of 40 N/m, 300 kHz,
/// Q = 400 tapping an SLS sample whose arm relaxes in τ_r = 3 ns, κℓ/α6 ≈ 2 over a part of 1/512
/// of the period: the stationary variances of the tip's deflection and rate from 512 parts per
/// period equal those of 32 768 parts (κℓ/α6 ≈ 0.03) within 10⁻³ (measured 10⁻⁵: the parts
/// across a switching carry little of u's noise).
#[test]
fn an_sls_chain_converges_in_its_parts() {
    let text = "model = \"point-mass\"\n[cantilever]\nspring_constant = 40\n\
                resonance_frequency = 300e3\nquality_factor = 400\n[tip]\nradius = 10e-9\n\
                [drive]\nfree_amplitude = 10e-9\n[sample]\nlaw = \"sls\"\nstiffness = 5.0\n\
                maxwell_stiffness = 10.0\nrelaxation_time = 3e-9\nz_c = 8e-9\n";
    let p = Probe::parse(text, "sls").expect("probe");
    let model = CantileverModel::new(&p.params).unwrap();
    let mut integ = build(
        &model,
        IntegratorOptions::default(),
        0.0,
        &DVector::zeros(3),
    )
    .unwrap();
    crate::integrate::advance(integ.as_mut(), 400.0 * model.period()).unwrap();
    let z = orbit(&model, integ.state());
    let kt = kt_model(&p);
    let variances = |parts: usize| {
        let (walk, contact) = walked(&model, &z, kt, parts);
        assert!(contact, "the orbit taps");
        let y = walk.chain.stationary().expect("a stable orbit");
        [y[(0, 0)], y[(1, 1)]]
    };
    let (coarse, fine) = (variances(512), variances(32_768));
    println!("512 parts {coarse:?}, 32 768 parts {fine:?}");
    for (c, f) in coarse.iter().zip(&fine) {
        assert!((c / f - 1.0).abs() < 1e-3, "{coarse:?} vs {fine:?}");
    }
}

/// The walk of `model`'s orbit through `z` at `kt` over one period in `parts` equal parts, and
/// whether it passed through contact.
fn walked<'a>(
    model: &'a CantileverModel,
    z: &DVector<f64>,
    kt: f64,
    parts: usize,
) -> (Walk<'a>, bool) {
    let mut walk = Walk::new(model, z, kt, 0, IntegratorOptions::default()).unwrap();
    let mut contact = false;
    for k in 1..=parts {
        walk.part(model.period() * k as f64 / parts as f64).unwrap();
        contact |= walk.region == Region::Contact;
    }
    (walk, contact)
}

/// JKR's neck holds the tip at V_T > 0, where the state alone says free flight: the walk carries
/// the region from part to part (`crate::analysis::orbit_noise`). A point mass (0.4 N/m, 70 kHz,
/// Q = 0.5) pulled slowly (f₀/f_m = 200) off a JKR sample (E_s = 1 GPa, ν_s = 0.3, a silicon
/// tip of R = 10 nm, W = 0.05 J/m², no viscosity): from the deepest indentation to the release
/// its deviation obeys m δẍ + c δẋ + (k + k_c(t)) δx = ξ, ξ white with 2k_BT c, k_c = dF/dδ of
/// Johnson's parametric JKR curve at the orbit's δ(t) (written here: F = 4E*a³/(3R) −
/// √(8πWE*a³), δ = a²/R − √(2πWa/E*); Johnson, *Contact Mechanics*, CUP 1985, §5.5), so that
/// its covariance P obeys the Lyapunov equation Ṗ = AP + PAᵀ + D, integrated here by RK4 from
/// the equilibrium one at the deepest point (whose error has decayed many times over by the
/// neck). The walk's variance of δx equals it within 10⁻⁴ (measured 10⁻⁵) in the neck (δ < 0),
/// hundreds of points, and in compression, up to the load-controlled pull-off and beyond while
/// k + k_c ≥ k/10. (A walk that took its region from the state would see no neck.)
#[test]
fn a_jkr_neck_fluctuates_as_its_stiffness_gives() {
    let text = "model = \"point-mass\"\n[cantilever]\nspring_constant = 0.4\n\
                resonance_frequency = 70e3\nquality_factor = 0.5\n[tip]\nradius = 10e-9\n\
                youngs_modulus = 169e9\npoisson_ratio = 0.27\n\
                [sample]\nlaw = \"jkr\"\nyoungs_modulus = 1e9\npoisson_ratio = 0.3\n\
                adhesion_energy = 0.05\nz_c = 10e-9\n\
                [drive]\nmode = \"off-resonance\"\nmodulation_frequency = 350\n\
                modulation_amplitude = 20e-9\n";
    let p = Probe::parse(text, "jkr").expect("probe");
    let model = CantileverModel::new(&p.params).unwrap();
    let z = settled_orbit(&model);
    let (kt, length, time) = (kt_model(&p), p.scales.length_m, p.scales.time_s);
    let (k, r, w, kt_si) = (0.4_f64, 10e-9_f64, 0.05_f64, BOLTZMANN * 295.0);
    let (mass, omega0) = (k / (TAU * 70e3).powi(2), TAU * 70e3);
    let damping = mass * omega0 / 0.5;
    let e_star = 1.0 / ((1.0 - 0.27_f64.powi(2)) / 169e9 + (1.0 - 0.3_f64.powi(2)) / 1e9);
    let pi = std::f64::consts::PI;
    let delta = |a: f64| a * a / r - (2.0 * pi * w * a / e_star).sqrt();
    // k + k_c at the indentation d on the branch a > a_f (dδ/da = 0 at a_f), a by bisection
    let a_f = (r * r * pi * w / (8.0 * e_star)).cbrt();
    let spring = |d: f64| {
        let (mut lo, mut hi) = (a_f, 1e-6);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            (lo, hi) = if delta(mid) < d { (mid, hi) } else { (lo, mid) };
        }
        let a = 0.5 * (lo + hi);
        let df = 4.0 * e_star * a * a / r - 1.5 * (8.0 * pi * w * e_star * a).sqrt();
        k + df / (2.0 * a / r - 0.5 * (2.0 * pi * w / (e_star * a)).sqrt())
    };
    // Ṗ = AP + PAᵀ + D for (Pxx, Pxv, Pvv), K(t) linear over [t0, t1], RK4 in 16 steps
    let lyapunov = |pm: [f64; 3], (t0, k0): (f64, f64), (t1, k1): (f64, f64)| {
        let rate = |t: f64, [xx, xv, vv]: [f64; 3]| {
            let kk = k0 + (k1 - k0) * (t - t0) / (t1 - t0);
            let (s, g) = (kk / mass, damping / mass);
            [
                2.0 * xv,
                vv - s * xx - g * xv,
                -2.0 * s * xv - 2.0 * g * vv + 2.0 * kt_si * g / mass,
            ]
        };
        let (mut y, dt) = (pm, (t1 - t0) / 16.0);
        for i in 0..16 {
            let t = t0 + i as f64 * dt;
            let add = |y: [f64; 3], d: [f64; 3], f: f64| [0, 1, 2].map(|j| y[j] + f * d[j]);
            let k1 = rate(t, y);
            let k2 = rate(t + dt / 2.0, add(y, k1, dt / 2.0));
            let k3 = rate(t + dt / 2.0, add(y, k2, dt / 2.0));
            let k4 = rate(t + dt, add(y, k3, dt));
            y = [0, 1, 2].map(|j| y[j] + dt / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]));
        }
        y
    };
    let (end, h) = (
        model.period(),
        ETA / crate::analysis::peakforce::first_natural_frequency(&model),
    );
    let walk = || Walk::new(&model, &z, kt, 0, IntegratorOptions::default()).unwrap();
    // the first walk: the stationary covariance, and the time of the deepest indentation
    let (mut first, mut peak) = (walk(), (0.0, f64::INFINITY));
    while first.tau < end {
        first.adaptive_part(end, h).unwrap();
        let v = model.v_t(first.tau, &first.state);
        if v < peak.1 {
            peak = (first.tau, v);
        }
    }
    let y = first.chain.stationary().expect("a stable orbit");
    let (mut walk, g) = (walk(), DVector::from_column_slice(&[1.0, 0.0]));
    let (mut neck, mut worst, mut ode) = (0, 0.0_f64, None);
    while walk.tau < end {
        walk.adaptive_part(end, h).unwrap();
        let (t, v) = (walk.tau * time, model.v_t(walk.tau, &walk.state));
        if walk.region != Region::Contact || walk.tau < peak.0 {
            continue;
        }
        let kk = spring(-v * length);
        let pm = match ode {
            None => [kt_si / kk, 0.0, kt_si / mass],
            Some((pm, at)) => lyapunov(pm, at, (t, kk)),
        };
        ode = Some((pm, (t, kk)));
        if kk < 0.1 * k {
            continue;
        }
        let got = walk.chain.variance(&y, &g) * length * length;
        neck += usize::from(v > 0.0);
        worst = worst.max((got / pm[0] - 1.0).abs());
    }
    println!("{neck} points in the neck; worst relative error {worst:.3e}");
    assert!(neck > 100, "{neck} points in the neck");
    assert!(worst < 1e-4, "{worst}");
}

/// While the impact law sticks, the constraint's reaction takes the thermal force's part at the
/// tip (M ä = f + φλ with φᵀä = 0: the diffusion P D Pᵀ, P = I − m_eff M⁻¹φφᵀ,
/// `crate::analysis::orbit_noise`). The paper's three-mode beam pressed into a hard sample
/// (α5 = −0.5, undriven: the tip held on the surface, λ > 0) is a beam pinned at its tip; its
/// stationary fluctuations are equipartition conditioned on the constraint φᵀa = −α5, the
/// conditional of N(ā, k_BT K⁻¹): Cov a = k_BT (K⁻¹ − K⁻¹φφᵀK⁻¹/(φᵀK⁻¹φ)), and on its tangent
/// space Cov ȧ = k_BT (M⁻¹ − M⁻¹φφᵀM⁻¹/(φᵀM⁻¹φ)). The chain over one period gives both within
/// 10⁻⁸ of their largest entry.
#[test]
fn a_sticking_tip_pins_the_beams_fluctuations() {
    use crate::system::HybridSystem;
    let p = crate::params::Params {
        contact_law: crate::contact::ContactLaw::Impact { restitution: 0.5 },
        alpha2: 0.0,
        alpha5: -0.5,
        ..crate::params::Params::default()
    };
    let model = CantileverModel::new(&p).unwrap();
    let (n, kt) = (model.modes(), 1e-3);
    let g = model.galerkin().region(Region::Free);
    let (k_inv, m_inv) = (
        g.stiffness.clone().try_inverse().unwrap(),
        g.mass.clone().try_inverse().unwrap(),
    );
    let phi = model.tip();
    let conditioned = |c: &DMatrix<f64>| {
        let cp = c * phi;
        (c - &cp * cp.transpose() / phi.dot(&cp)) * kt
    };
    // the pinned rest state, a hair inside the surface
    let k_phi = &k_inv * phi;
    let mut z = DVector::zeros(2 * n);
    z.rows_mut(0, n)
        .copy_from(&(&k_phi * (-p.alpha5 * (1.0 - 1e-14) / phi.dot(&k_phi))));
    assert_eq!(
        model.mode_at(0.0, z.as_slice()),
        Region::Contact,
        "the tip sticks"
    );
    let mut walk = Walk::new(&model, &z, kt, 0, IntegratorOptions::default()).unwrap();
    let parts = 64;
    for k in 1..=parts {
        walk.part(model.period() * k as f64 / parts as f64).unwrap();
        assert_eq!(walk.region, Region::Contact, "the tip stays on the surface");
    }
    let y = walk.chain.stationary().expect("a stable chain");
    for (block, want) in [(0, conditioned(&k_inv)), (n, conditioned(&m_inv))] {
        let got = y.view((block, block), (n, n));
        let err = (got - &want).amax() / want.amax();
        println!("block {block}: {err:.3e}");
        assert!(err < 1e-8, "{got} vs {want}");
    }
}

/// An impacting orbit's chain: free flights exact (Van Loan), each impact's jump carried by its
/// saltation matrix, the parts across a switching by the trapezoid rule
/// (`crate::analysis::orbit_noise`). A point mass of 40 N/m, 300 kHz, Q = 400 tapping a rigid
/// sample (Newton's restitution r) at z_c = 5 nm under A₀ = 10 nm: the stationary variances of
/// the tip's deflection and rate from 512 parts per period equal those of 32 768 parts within
/// 10⁻³ (measured 10⁻⁷), for r = 0.5 and r = 0 (plastic: the tip leaves the surface at once,
/// its rate zeroed). The orbit is said to graze, beyond the linear response, where its impacts'
/// speed falls below 5 thermal speeds √(k_BT/m_eff): at 0.9 and 1.1 times the k_BT of that
/// threshold (the speed from the events' V̇_T⁻ here), not and then so.
#[test]
fn an_impacting_chain_converges_in_its_parts() {
    for r in [0.5, 0.0] {
        let text = format!(
            "model = \"point-mass\"\n[cantilever]\nspring_constant = 40\n\
             resonance_frequency = 300e3\nquality_factor = 400\n[tip]\nradius = 10e-9\n\
             [drive]\nfree_amplitude = 10e-9\n[sample]\nlaw = \"impact\"\n\
             restitution = {r}\nz_c = 5e-9\n"
        );
        let p = Probe::parse(&text, "impact").expect("probe");
        let model = CantileverModel::new(&p.params).unwrap();
        let z = settled_orbit(&model);
        // the orbit's switchings over a period
        let mut integ = build(&model, IntegratorOptions::default(), 0.0, &z).unwrap();
        let (mut impacts, mut speeds) = (0, 0.0);
        while integ.tau() < model.period() {
            if let Some(e) = integ.step(model.period()).unwrap().event {
                impacts += 1;
                speeds += e.v_t_dot * e.v_t_dot;
            }
        }
        assert!(impacts >= 1, "r = {r}: the orbit impacts");
        // its own grazing (`orbit_noise::grazing`): its impacts' mean square speed v² against
        // 25 k_BT/m_eff, v² here from the events' V̇_T⁻, there from the impacts' energy loss
        let v2 = speeds / impacts as f64;
        let observed = crate::analysis::observables::observe_from(
            &model,
            IntegratorOptions::default(),
            0.0,
            &z,
            &Default::default(),
        )
        .unwrap();
        let at = |kt: f64| {
            let o = std::iter::once(&observed);
            crate::analysis::orbit_noise::grazing(model.params(), kt, o).unwrap()
        };
        let threshold = v2 * model.effective_mass() / 25.0;
        assert_eq!(
            (at(0.9 * threshold), at(1.1 * threshold)),
            (0, 1),
            "r = {r}"
        );
        let kt = kt_model(&p);
        let variances = |parts: usize| {
            let y = walked(&model, &z, kt, parts).0.chain;
            let y = y.stationary().expect("a stable orbit");
            [y[(0, 0)], y[(1, 1)]]
        };
        let (coarse, fine) = (variances(512), variances(32_768));
        println!(
            "r = {r}: {impacts} switchings per period; 512 parts {coarse:?}, 32 768 parts \
             {fine:?}"
        );
        for (c, f) in coarse.iter().zip(&fine) {
            assert!((c / f - 1.0).abs() < 1e-3, "{coarse:?} vs {fine:?}");
        }
    }
}

/// An impacting chain against a simulation written here, independent of the chain and of the
/// stochastic step: a point mass of 40 N/m, 300 kHz, Q = 10 tapping a rigid sample (r = 0.5)
/// at z_c = 5 nm under A₀ = 10 nm, its impacts 170 thermal speeds √(k_BT/m_eff) fast (far from
/// grazing, where the linear response holds). The simulation is the Euler–Maruyama scheme
/// (semi-implicit: the rate first, then the position; Kloeden & Platen, *Numerical Solution of
/// Stochastic Differential Equations*, Springer 1992, §10.2) over the model's drift and the
/// thermal force's diffusion, 4 000 steps per period; an impact is where V_T turns negative
/// within a step, at the linear interpolation's time, where Newton's restitution reverses the
/// rate, ȧ⁺ = −r ȧ⁻ (one mode), the step finished from there. The chain's F is the
/// finite-difference monodromy of the deterministic DOP853 map within 10⁻⁵, and the state's
/// variances at the period's start over 10 000 periods are the chain's stationary ones within
/// 5 standard errors (batch means over 40 batches) and 3 % (the scheme's own bias, O(dt):
/// measured +3.5 % and +1 % at 2 000 steps, −2 % and −2.3 % at 8 000, ±1.7 % each).
#[test]
fn an_impacting_chain_is_the_simulated_oscillators() {
    use rand::{RngExt, SeedableRng};
    let text = "model = \"point-mass\"\n[cantilever]\nspring_constant = 40\n\
                resonance_frequency = 300e3\nquality_factor = 10\n[tip]\nradius = 10e-9\n\
                [drive]\nfree_amplitude = 10e-9\n[sample]\nlaw = \"impact\"\n\
                restitution = 0.5\nz_c = 5e-9\n";
    let p = Probe::parse(text, "impact").expect("probe");
    let model = CantileverModel::new(&p.params).unwrap();
    let z0 = settled_orbit(&model);
    let kt = kt_model(&p);
    let walk = walked(&model, &z0, kt, 4096).0;
    let chain = walk.chain.stationary().expect("a stable orbit");
    // the deterministic map's monodromy by central differences (DOP853 at 10⁻¹²)
    let opts = IntegratorOptions {
        tolerance: 1e-12,
        kind: crate::integrate::IntegratorKind::Adaptive,
        ..IntegratorOptions::default()
    };
    let end = |z: DVector<f64>| {
        let mut it = build(&model, opts.clone(), 0.0, &z).unwrap();
        let mut speed: f64 = 0.0;
        while it.tau() < model.period() {
            if let Some(e) = it.step(model.period()).unwrap().event {
                speed = speed.max(e.v_t_dot.abs());
            }
        }
        (it.state().clone(), speed)
    };
    let mut fd = DMatrix::zeros(2, 2);
    for j in 0..2 {
        let dz = DVector::from_fn(2, |i, _| if i == j { 1e-7 } else { 0.0 });
        fd.set_column(j, &((end(&z0 + &dz).0 - end(&z0 - &dz).0) / 2e-7));
    }
    let gap = (&fd - &walk.chain.f).norm() / fd.norm();
    let speed = end(z0.clone()).1 / (kt / model.effective_mass()).sqrt();
    println!("monodromy within {gap:.1e}; impacts at {speed:.0} thermal speeds");
    assert!(gap < 1e-5, "{fd} against {}", walk.chain.f);
    assert!(speed > 25.0, "{speed}: the orbit grazes");
    // Euler–Maruyama with impacts
    let d = crate::integrate::exact::noise::diffusion(&model, Region::Free, kt);
    let (steps, burn, batches, per) = (4000, 200, 40, 250);
    let (period, restitution) = (model.period(), 0.5);
    let dt = period / steps as f64;
    let kick = (d[(1, 1)] * dt).sqrt();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let (mut z, mut f) = (z0.clone(), DVector::zeros(2));
    let mut series = [Vec::new(), Vec::new()];
    for n in 0..burn + batches * per {
        for k in 0..steps {
            let tau = period * n as f64 + dt * k as f64;
            model.rhs(Region::Free, tau, &z, &mut f);
            let (x0, v0) = (z[0], model.v_t(tau, &z));
            let xi: f64 = rng.sample(rand_distr::StandardNormal);
            z[1] += f[1] * dt + kick * xi;
            z[0] += z[1] * dt;
            let v1 = model.v_t(tau + dt, &z);
            if v1 < 0.0 && v0 >= 0.0 {
                let s = v0 / (v0 - v1);
                let rate = -restitution * z[1];
                z[0] = x0 + s * (z[0] - x0) + rate * (1.0 - s) * dt;
                z[1] = rate;
            }
        }
        if n >= burn {
            series[0].push(z[0]);
            series[1].push(z[1]);
        }
    }
    for (j, s) in series.iter().enumerate() {
        let [var, se] = batch_variance(s, per, batches);
        let want = chain[(j, j)];
        println!("{j}: simulated {var:.5e} ± {se:.1e}, the chain's {want:.5e}");
        assert!(
            (var - want).abs() < 5.0 * se + 0.03 * want,
            "{j}: {var} ± {se} against {want}"
        );
    }
}

//! The exact stochastic step against its sources: the covariance integral Q(h) against the
//! Lyapunov equation it solves (d Q/dh = Φ GGᵀ Φᵀ, so A Q + Q Aᵀ + GGᵀ = Φ GGᵀ Φᵀ; Van Loan 1978)
//! and its limit, the stationary P = diag(k_BT K⁻¹, k_BT M⁻¹); a free lever's simulated
//! ⟨η_k²⟩ per mode and tip ⟨x²⟩ against equipartition as `crate::analysis::thermal` gives it,
//! and its Welch periodogram against the thermal spectrum, within their statistical errors at a
//! fixed seed; the stream a function of the seed alone; switchings the noise makes between two
//! grid points found at a coarse grid as at a fine one.

use super::*;
use crate::analysis::progress::Progress;
use crate::analysis::thermal::{thermal_spectrum, ModelUnits, BOLTZMANN};
use crate::eigen::natural_modes;
use crate::probe::Probe;

/// examples/probe-water-beam.toml (three modes in water, Q₁ ≈ 2.3) over a linear sample
/// (k = 1 N/m) at `z_c` (m) with a drive of `a0` (m; 0: undriven, α2 = 0).
fn water_linear(z_c: f64, a0: f64) -> Probe {
    water(
        &format!("law = \"linear\"\nstiffness = 1.0\nz_c = {z_c}"),
        a0,
    )
}

/// examples/probe-water-beam.toml over the sample of the `[sample]` section's body `sample`,
/// with a drive of `a0` (m; 0: undriven, α2 = 0).
fn water(sample: &str, a0: f64) -> Probe {
    let text = include_str!("../../../../../../examples/probe-water-beam.toml");
    let (head, rest) = text.split_at(text.find("[sample]").unwrap());
    let tail = &rest[rest.find("[drive]").unwrap()..];
    let drive = if a0 > 0.0 { a0 } else { 1e-9 };
    let tail = tail.replace(
        "free_amplitude = 10e-9",
        &format!("free_amplitude = {drive}"),
    );
    let text = format!("{head}[sample]\n{sample}\n{tail}");
    let mut p = Probe::parse(&text, "water").expect("probe");
    if a0 == 0.0 {
        p.params.alpha2 = 0.0;
    }
    p
}

/// k_B T at 295 K in the model's energy unit of `p` (force × length).
fn kt_model(p: &Probe) -> f64 {
    BOLTZMANN * 295.0 / (p.scales.force_n * p.scales.length_m)
}

fn units(p: &Probe) -> ModelUnits {
    ModelUnits {
        length_m: p.scales.length_m,
        force_n: p.scales.force_n,
        time_s: p.scales.time_s,
    }
}

/// A run of `p` at 295 K with `seed`, `min_steps` steps per period at least, over `periods`:
/// (τ, z) at every grid point, the integrator, the time in contact and the switchings.
fn run_counting(
    p: &Probe,
    seed: u64,
    min_steps: usize,
    periods: f64,
) -> (Vec<(f64, Vec<f64>)>, ThermalExact, f64, usize) {
    let model = CantileverModel::new(&p.params).unwrap();
    let opts = IntegratorOptions {
        steps_per_period: min_steps,
        ..IntegratorOptions::default()
    };
    let force = ThermalForce::new(kt_model(p), seed);
    let mut it = ThermalExact::new(&model, &opts, force).unwrap();
    it.reset(0.0, &model.rest()).unwrap();
    let end = periods * model.period();
    let mut out = Vec::new();
    let (mut contact, mut switchings) = (0.0, 0);
    while it.tau() < end {
        let step = it.step(end).unwrap();
        if step.region == Region::Contact {
            contact += step.tau1 - step.tau0;
        }
        switchings += usize::from(step.event.is_some());
        out.push((it.tau(), it.state().as_slice().to_vec()));
    }
    (out, it, contact, switchings)
}

/// [`run_counting`]'s series and integrator.
fn run(
    p: &Probe,
    seed: u64,
    min_steps: usize,
    periods: f64,
) -> (Vec<(f64, Vec<f64>)>, ThermalExact) {
    let (out, it, _, _) = run_counting(p, seed, min_steps, periods);
    (out, it)
}

/// Q(h) from Van Loan's block exponential solves A Q + Q Aᵀ + GGᵀ = Φ GGᵀ Φᵀ (the derivative of
/// its definition) at a small and a large step, in both regions of a three-mode beam with a tip
/// mass; doubled (Q(2h) = Q(h) + Φ Q(h) Φᵀ) to many relaxation times it is the stationary
/// P = diag(k_BT K⁻¹, k_BT M⁻¹), the Lyapunov equation's solution A P + P Aᵀ + GGᵀ = 0.
#[test]
fn the_covariance_integral_solves_the_lyapunov_equation() {
    let p = crate::params::Params {
        modes: 3,
        alpha1: 0.5,
        ..crate::params::Params::default()
    };
    let model = CantileverModel::new(&p).unwrap();
    let kt = 1e-3;
    for r in [Region::Free, Region::Contact] {
        let a = &model.dynamics(r).a;
        let d = diffusion(&model, r, kt);
        for h in [1e-3, 0.7] {
            let (phi, q) = van_loan(a, &d, h);
            let lhs = a * &q + &q * a.transpose() + &d;
            let rhs = &phi * &d * phi.transpose();
            let err = (&lhs - &rhs).norm() / d.norm();
            assert!(err < 1e-10, "{r:?} h = {h}: residual {err:e}");
        }
        let (phi, mut q) = van_loan(a, &d, 0.05);
        let mut phi_n = phi;
        for _ in 0..16 {
            q = &q + &phi_n * &q * phi_n.transpose();
            phi_n = &phi_n * &phi_n;
        }
        let g = model.galerkin().region(r);
        let n = p.modes;
        let mut pst = DMatrix::zeros(2 * n, 2 * n);
        let kinv = g.stiffness.clone().try_inverse().unwrap() * kt;
        let minv = g.mass.clone().try_inverse().unwrap() * kt;
        pst.view_mut((0, 0), (n, n)).copy_from(&kinv);
        pst.view_mut((n, n), (n, n)).copy_from(&minv);
        let err = (&q - &pst).norm() / pst.norm();
        assert!(err < 1e-9, "{r:?}: Q(∞) against P: {err:e}");
    }
}

/// The free lever's simulated mean squares against equipartition (Butt & Jaschke 1995 through
/// `thermal_spectrum`): each natural mode's ⟨η_k²⟩ = k_BT/ω_k² and the tip's ⟨x²⟩ over the
/// modes, within 5 standard errors of a variance estimated over a run of length 𝒯 with the
/// mode's correlation time Q_k/ω_k: σ(ŝ²)/s² = (2 Q_k/(ω_k 𝒯))^{1/2}.
#[test]
fn a_free_lever_holds_equipartition() {
    let p = water_linear(1e-6, 0.0);
    let spectrum =
        thermal_spectrum(&p.params, units(&p), 295.0, 1.0, &[], &Progress::default()).unwrap();
    let periods = 4000.0;
    let (series, it) = run(&p, 7, 1, periods);
    let model = it.model().clone();
    let g = model.galerkin().region(crate::galerkin::Region::Free);
    let nat = natural_modes(g);
    let q = crate::eigen::quality_factors(g);
    let n = model.modes();
    let kt = it.force().kt;
    let zp = |t: f64| it.zp(Region::Free, t, (it.model().omega() * t).sin_cos());
    let mut sums = vec![0.0; n + 1];
    let skip = series.len() / 20;
    for (t, z) in &series[skip..] {
        let dz = DVector::from_column_slice(z) - zp(*t);
        let a = dz.rows(0, n).into_owned();
        let eta = nat.vectors.transpose() * &g.mass * &a;
        for k in 0..n {
            sums[k] += eta[k] * eta[k];
        }
        sums[n] += model.tip().dot(&a).powi(2);
    }
    let count = (series.len() - skip) as f64;
    let span = periods * model.period() * 0.95;
    let l2 = p.scales.length_m.powi(2);
    let mut worst: f64 = 0.0;
    for k in 0..n {
        let w = nat.omega[k];
        let ratio = sums[k] / count / (kt / (w * w));
        let sigma = (2.0 * q[k].unwrap_or(0.5) / (w * span)).sqrt();
        println!("mode {}: ratio {ratio:.4} ± {sigma:.4}", k + 1);
        assert!((ratio - 1.0).abs() < 5.0 * sigma, "mode {}: {ratio}", k + 1);
        worst = worst.max(sigma);
    }
    let tip = sums[n] / count * l2 / spectrum.mean_square_deflection;
    let w1 = nat.omega[0];
    let sigma = (2.0 * q[0].unwrap_or(0.5) / (w1 * span)).sqrt();
    println!("tip: ratio {tip:.4} ± {sigma:.4}");
    assert!((tip - 1.0).abs() < 5.0 * sigma, "tip {tip}");
}

/// The tip's Welch periodogram (Hann windows, half overlap) of a simulated free series against
/// `thermal_spectrum`'s S_x(f) over 0.3–3 f₁: the mean ratio within 5 standard errors of K
/// segments averaged over B bins (σ ≈ (K B/2)^{-1/2}, adjacent Hann bins correlated).
#[test]
fn a_free_series_has_the_thermal_spectrum() {
    use rustfft::{num_complex::Complex, FftPlanner};
    let p = water_linear(1e-6, 0.0);
    let (series, it) = run(&p, 11, 1, 3000.0);
    let model = it.model().clone();
    let n = model.modes();
    let x: Vec<f64> = (series.iter())
        .map(|(t, z)| {
            let dz = DVector::from_column_slice(z)
                - it.zp(Region::Free, *t, (it.model().omega() * t).sin_cos());
            model.tip().dot(&dz.rows(0, n)) * p.scales.length_m
        })
        .collect();
    let dt = it.det.grid.h * p.scales.time_s;
    let seg = 1024;
    let win: Vec<f64> = (0..seg)
        .map(|i| 0.5 - 0.5 * (std::f64::consts::TAU * i as f64 / seg as f64).cos())
        .collect();
    let norm: f64 = win.iter().map(|w| w * w).sum::<f64>();
    let fft = FftPlanner::new().plan_fft_forward(seg);
    let mut psd = vec![0.0; seg / 2];
    let mut k = 0;
    let mut start = 0;
    while start + seg <= x.len() {
        let mut buf: Vec<Complex<f64>> = (0..seg)
            .map(|i| Complex::new(x[start + i] * win[i], 0.0))
            .collect();
        fft.process(&mut buf);
        for (i, s) in psd.iter_mut().enumerate().skip(1) {
            *s += 2.0 * buf[i].norm_sqr() * dt / norm;
        }
        k += 1;
        start += seg / 2;
    }
    let f: Vec<f64> = (0..seg / 2).map(|i| i as f64 / (seg as f64 * dt)).collect();
    let spectrum = thermal_spectrum(
        &p.params,
        units(&p),
        295.0,
        1.0,
        &f[1..],
        &Progress::default(),
    )
    .unwrap();
    let f1 = spectrum.modes[0].frequency;
    let bins: Vec<usize> = (1..seg / 2)
        .filter(|&i| f[i] > 0.3 * f1 && f[i] < 3.0 * f1)
        .collect();
    let ratio = bins
        .iter()
        .map(|&i| psd[i] / k as f64 / spectrum.deflection[i - 1])
        .sum::<f64>()
        / bins.len() as f64;
    let sigma = (2.0 / (k as f64 * bins.len() as f64)).sqrt();
    println!(
        "Welch/FDT over {} bins, {k} segments: {ratio:.4} ± {sigma:.4}",
        bins.len()
    );
    assert!((ratio - 1.0).abs() < 5.0 * sigma + 0.01, "{ratio}");
}

/// The same seed gives the same series bit for bit, in a pool of one thread and of two; another
/// seed another one.
#[cfg(feature = "parallel")]
#[test]
fn the_stream_is_the_seeds() {
    let p = water_linear(1e-6, 5e-9);
    let series = |seed: u64, threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| run(&p, seed, 1, 20.0).0)
    };
    let a = series(3, 1);
    assert_eq!(a, series(3, 2));
    assert_ne!(a, series(4, 1));
}

/// Undriven, 0.3 thermal standard deviations above the sample, the lever touches it at random:
/// the fraction of time in contact at the propagator's own grid and at an 8× finer one agree
/// within 5 of their standard errors (the bridge finds between two coarse grid points the
/// switchings the fine grid sees); the coarse grid points alone see fewer switchings.
#[test]
fn the_bridge_finds_the_crossings_a_coarse_grid_misses() {
    let sd = (crate::analysis::thermal::BOLTZMANN * 295.0 / 0.19_f64).sqrt();
    let p = water_linear(0.3 * sd, 0.0);
    let periods = 1500.0;
    let (coarse, it, c_coarse, s_coarse) = run_counting(&p, 5, 1, periods);
    let m = it.steps_per_period();
    let (_, _, c_fine, s_fine) = run_counting(&p, 6, 8 * m, periods);
    let total = periods * it.model().period();
    let (f_coarse, f_fine) = (c_coarse / total, c_fine / total);
    // grid points in contact, and their changes of region: what the grid alone sees
    let h = it.det.grid.h;
    let sc = |t: f64| (it.model().omega() * t).sin_cos();
    let on_grid: Vec<&(f64, Vec<f64>)> = (coarse.iter())
        .filter(|(t, _)| ((t / h) - (t / h).round()).abs() < 1e-6)
        .collect();
    let grid_changes = (on_grid.windows(2))
        .filter(|w| {
            (it.gap(
                Region::Free,
                w[0].0,
                sc(w[0].0),
                &DVector::from_column_slice(&w[0].1),
            ) > 0.0)
                != (it.gap(
                    Region::Free,
                    w[1].0,
                    sc(w[1].0),
                    &DVector::from_column_slice(&w[1].1),
                ) > 0.0)
        })
        .count();
    // the contact episodes are independent over the first mode's correlation time
    let nat = natural_modes(it.model().galerkin().region(crate::galerkin::Region::Free));
    let q1 =
        crate::eigen::quality_factors(it.model().galerkin().region(crate::galerkin::Region::Free))
            [0]
        .unwrap_or(0.5);
    let independent = total * nat.omega[0] / (2.0 * q1);
    let sigma = (f_fine * (1.0 - f_fine) / independent).sqrt() * 2.0;
    println!(
        "m = {m}: contact fraction {f_coarse:.4} (coarse, {s_coarse} switchings; the grid \
         points change sides {grid_changes} times) against {f_fine:.4} (8×, {s_fine}), σ {sigma:.4}"
    );
    assert!((f_coarse - f_fine).abs() < 5.0 * sigma);
    assert!(s_coarse > grid_changes);
}

/// `simulate`'s `temperature`: refused without a probe (naming `temperature`), taken for DMT
/// and JKR (the exponential Euler step), SLS and the impact law (exact); with the
/// linear probe the same seed records the same run
/// and another seed another one; no temperature is the deterministic integrator.
#[test]
fn simulate_takes_a_temperature_with_a_probe() {
    use crate::request::simulate::SimulateRequest;
    let p = water_linear(8e-9, 10e-9);
    let model = CantileverModel::new(&p.params).unwrap();
    let request = |t: Option<f64>, seed: u64| SimulateRequest {
        periods: Some(5.0),
        temperature: t,
        seed,
        samples_per_period: 50,
        ..SimulateRequest::default()
    };
    let span = request(Some(295.0), 0)
        .validate_in_memory(&p.params)
        .unwrap();
    match request(Some(295.0), 0).record_whole(&model, None, &span) {
        Err(SimError::OutOfRange { name, .. }) => assert_eq!(name, "temperature"),
        other => panic!("{other:?}"),
    }
    let text = include_str!("../../../../../../examples/probe-water-beam.toml");
    let dmt = Probe::parse(text, "w").unwrap();
    let dmt_model = CantileverModel::new(&dmt.params).unwrap();
    let (_, name) = (request(Some(295.0), 0))
        .record_whole(&dmt_model, Some(&dmt), &span)
        .unwrap();
    assert_eq!(name, "exponential-euler-thermal");
    // JKR's region is the run's own (its neck); SLS's dashpot's extension is a state of the
    // exact step; the impact law's impacts and sticking are the exact step's events
    let over = |sample: &str| {
        let probe = water(sample, 10e-9);
        let model = CantileverModel::new(&probe.params).unwrap();
        request(Some(295.0), 0).record_whole(&model, Some(&probe), &span)
    };
    let jkr =
        over("law = \"jkr\"\nyoungs_modulus = 50e6\npoisson_ratio = 0.45\nadhesion_energy = 0.01");
    assert_eq!(jkr.unwrap().1, "exponential-euler-thermal");
    let sls =
        over("law = \"sls\"\nstiffness = 1.0\nmaxwell_stiffness = 1.0\nrelaxation_time = 1e-6");
    assert_eq!(sls.unwrap().1, "exact-thermal");
    let impact = over("law = \"impact\"\nrestitution = 0.5\nz_c = 8e-9");
    assert_eq!(impact.unwrap().1, "exact-thermal");
    let run = |seed| {
        let (tr, name) = (request(Some(295.0), seed))
            .record_whole(&model, Some(&p), &span)
            .unwrap();
        assert_eq!(name, "exact-thermal");
        tr.samples.iter().map(|s| s.v_t).collect::<Vec<f64>>()
    };
    assert_eq!(run(1), run(1));
    assert_ne!(run(1), run(2));
    let (_, name) = request(None, 0)
        .record_whole(&model, Some(&p), &span)
        .unwrap();
    assert_eq!(name, "exact");
}

/// The point-mass lever (40 N/m, 300 kHz) of quality factor `q` over a linear sample out of
/// reach, undriven.
fn point_mass(q: f64) -> Probe {
    let text = format!(
        "model = \"point-mass\"\n[cantilever]\nspring_constant = 40.0\n\
         resonance_frequency = 300e3\nquality_factor = {q}\n[tip]\nradius = 10e-9\n\
         [sample]\nlaw = \"linear\"\nstiffness = 1.0\nz_c = 1e-6\n\
         [drive]\nfree_amplitude = 1e-9\nfrequency = 300e3\n"
    );
    let mut p = Probe::parse(&text, "point mass").expect("probe");
    p.params.alpha2 = 0.0;
    p
}

/// From rest the lever's ensemble variance at time t is ⟨x²(t)⟩ = (2ck_BT/m²) ∫₀ᵗ G(u)² du,
/// G(u) = e^{−βu/2} sin(ω_d u)/ω_d the oscillator's impulse response (β = c/m, ω_d² = k/m −
/// β²/4; the Langevin oscillator, S. Chandrasekhar, *Rev. Mod. Phys.* 15 (1943) 1, ch. II §3),
/// integrated here by Simpson's rule on m, c, k of the model's free region: the exact stochastic
/// step's variance after 3 periods from rest, over 3000 runs (one stream), agrees within 5
/// standard errors (√(2/runs) of the variance) at Q = 2 (water), 400 (air) and 20 000 (vacuum),
/// where the variance has reached 1, 0.05 and 0.001 of equipartition.
#[test]
fn the_ensemble_from_rest_follows_the_oscillators_response() {
    for q in [2.0, 400.0, 20_000.0] {
        let p = point_mass(q);
        let model = CantileverModel::new(&p.params).unwrap();
        let g = model.galerkin().region(crate::galerkin::Region::Free);
        let (m, c, k) = (g.mass[(0, 0)], g.damping[(0, 0)], g.stiffness[(0, 0)]);
        let kt = kt_model(&p);
        let t = 3.0 * model.period();
        let (beta, wd) = (c / m, (k / m - (c / m).powi(2) / 4.0).sqrt());
        let green2 = |u: f64| ((-beta * u).exp() * (wd * u).sin().powi(2)) / (wd * wd);
        let steps = 200_000;
        let du = t / steps as f64;
        let simpson: f64 = (0..=steps)
            .map(|i| {
                let w = if i == 0 || i == steps {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                w * green2(i as f64 * du)
            })
            .sum::<f64>()
            * du
            / 3.0;
        let want = 2.0 * c * kt / (m * m) * simpson;
        let opts = IntegratorOptions::default();
        // every grid point held, and one point per period (free flight across each period)
        for (held, seed) in [(None, 17), (Some(1), 18)] {
            let it = ThermalExact::new(&model, &opts, ThermalForce::new(kt, seed)).unwrap();
            let mut it = match held {
                Some(samples) => it.holding(samples),
                None => it,
            };
            let runs = 3000;
            let (mut sum, mut steps) = (0.0, 0);
            for _ in 0..runs {
                it.reset(0.0, &model.rest()).unwrap();
                while it.tau() < t {
                    it.step(t).unwrap();
                    steps += 1;
                }
                let dz = it.state() - it.zp(Region::Free, t, (model.omega() * t).sin_cos());
                sum += model.tip().dot(&dz.rows(0, 1)).powi(2);
            }
            let got = sum / runs as f64;
            let sigma = (2.0 / runs as f64).sqrt();
            println!(
                "Q = {q}, held {held:?}: ⟨x²⟩ {got:.4e} against {want:.4e} ({:.4} of k_BT/k), \
                 {steps} steps",
                want * k / kt
            );
            assert!(
                (got / want - 1.0).abs() < 5.0 * sigma,
                "Q = {q}, held {held:?}: {got} against {want}"
            );
            if held.is_some() {
                assert_eq!(steps, 3 * runs, "one free-flight step per period");
            }
        }
    }
}

/// Free flight against the deterministic exact propagator as k_BT → 0: the driven water beam
/// far from the sample, from rest (a transient), held once per period, steps across whole
/// periods (one step per period) and lands on the propagator's states at the period ends.
#[test]
fn free_flight_is_the_propagators_step_as_the_temperature_vanishes() {
    let p = water_linear(1e-6, 5e-9);
    let model = CantileverModel::new(&p.params).unwrap();
    let opts = IntegratorOptions::default();
    let mut it = ThermalExact::new(&model, &opts, ThermalForce::new(1e-30, 3))
        .unwrap()
        .holding(1);
    it.reset(0.0, &model.rest()).unwrap();
    let mut det = crate::integrate::build(&model, opts, 0.0, &model.rest()).unwrap();
    for k in 1..=6 {
        let t = k as f64 * model.period();
        let step = it.step(t).unwrap();
        assert_eq!((step.tau0, step.tau1), ((k - 1) as f64 * model.period(), t));
        crate::integrate::advance(det.as_mut(), t).unwrap();
        let err = (it.state() - det.state()).norm() / det.state().norm();
        assert!(err < 1e-10, "period {k}: {err:e}");
    }
}

/// Tapping, held once per period, the lever steps across the far part of its period in free
/// flight (steps longer than the grid's, the window's least V_T clearing the surface) and on the
/// grid, searched, near the sample: its time in contact per period and its switchings per period
/// agree with the run holding every grid point (no free flight longer than a grid step) within
/// 5 standard errors of their per-period means (periods 20–400, after the transient).
#[test]
fn a_tapping_lever_flies_free_only_far_from_the_surface() {
    let p = water_linear(4e-9, 5e-9);
    let model = CantileverModel::new(&p.params).unwrap();
    let opts = IntegratorOptions::default();
    let period = model.period();
    let run = |held: bool| {
        let it = ThermalExact::new(&model, &opts, ThermalForce::new(kt_model(&p), 9)).unwrap();
        let h = period / it.steps_per_period() as f64;
        let mut it = if held { it.holding(1) } else { it };
        it.reset(0.0, &model.rest()).unwrap();
        let (mut longest, mut per_period) = (0.0_f64, Vec::new());
        for k in 1..=400 {
            let end = k as f64 * period;
            let (mut contact, mut events) = (0.0, 0.0);
            while it.tau() < end {
                let s = it.step(end).unwrap();
                longest = longest.max((s.tau1 - s.tau0) / h);
                if s.region == Region::Contact {
                    contact += (s.tau1 - s.tau0) / period;
                }
                events += f64::from(u8::from(s.event.is_some()));
            }
            if k > 20 {
                per_period.push([contact, events]);
            }
        }
        let n = per_period.len() as f64;
        let stats = [0, 1].map(|i| {
            let mean = per_period.iter().map(|v| v[i]).sum::<f64>() / n;
            let var = per_period
                .iter()
                .map(|v| (v[i] - mean).powi(2))
                .sum::<f64>()
                / (n - 1.0);
            (mean, (var / n).sqrt())
        });
        (longest, stats)
    };
    let (longest, held) = run(true);
    let (grid_longest, every) = run(false);
    println!("longest step {longest:.1} h (every point held: {grid_longest:.2} h)");
    assert!(longest > 2.0 && grid_longest <= 1.0 + 1e-9);
    for (what, (a, sa), (b, sb)) in [
        ("contact", held[0], every[0]),
        ("switchings", held[1], every[1]),
    ] {
        println!("{what} per period: {a:.5} ± {sa:.5} against {b:.5} ± {sb:.5}");
        assert!(
            b > 0.0 && (a - b).abs() <= 5.0 * sa.hypot(sb) + 1e-12,
            "{what}: {a} against {b}"
        );
    }
}

/// [`least_of_sine`] against the least of 10⁵ points of the window, windows inside a period, across
/// a minimum and longer than a period.
#[test]
fn the_least_of_a_sine_over_a_window() {
    for (t0, t1) in [
        (0.1, 0.5),
        (4.0, 5.0),
        (-2.0, -1.9),
        (1.0, 9.0),
        (5.0, 4.0 + 6.3),
    ] {
        let want = (0..=100_000)
            .map(|i| 0.3 + 2.0 * (t0 + (t1 - t0) * i as f64 / 1e5).sin())
            .fold(f64::INFINITY, f64::min);
        let got = least_of_sine(0.3, 2.0, t0, t1);
        assert!(
            (got - want).abs() < 1e-9,
            "[{t0}, {t1}]: {got} against {want}"
        );
    }
}

/// The lock-in's output noise on a driven free lever against the linear response from the
/// thermal spectrum: with W = W_p + n, n the stationary thermal motion of one-sided PSD S(f)
/// (`thermal_spectrum`), the lock-in's output after period K is linear in the samples n(t_s),
/// Σ_s c_s n(t_s), with c_s = β(1 − β)^k (2/M) sin(θ_j − φ) for the amplitude (cos for A δφ) at
/// sample j of period K − k (`crate::analysis::am_loop`'s rectangle rule and first-order
/// low-pass), so Var = ∫₀^∞ S(f) |Σ_s c_s e^{2πi f t_s}|² df (R(t) = ∫₀^∞ S(f) cos 2πft df):
/// |G(f)|² |D(f)|² with G(f) = β/(1 − (1 − β)e^{−2πifT}) and D(f) = (2/M) Σ_j sin(θ_j − φ)
/// e^{2πif jT/M}. Simulated over 30 000 periods (τ_L = 8T) within 5 standard errors of an
/// AR(1) output's variance estimate, σ ≈ (2(1 + ρ²)/((1 − ρ²)P))^{1/2}, ρ = 1 − β.
#[test]
fn the_lock_in_output_carries_the_thermal_noise_of_its_bandwidth() {
    use crate::analysis::am_loop::{demodulate_period, LockIn};
    let p = water_linear(1e-6, 5e-9);
    let model = CantileverModel::new(&p.params).unwrap();
    let samples = 32;
    let opts = IntegratorOptions {
        steps_per_period: holding_samples(1, samples),
        ..IntegratorOptions::default()
    };
    let mut it = ThermalExact::new(&model, &opts, ThermalForce::new(kt_model(&p), 5)).unwrap();
    let z0 = it.zp(Region::Free, 0.0, (0.0, 1.0));
    it.reset(0.0, &z0).unwrap();
    let period = model.period();
    let time_constant = 8.0 * period;
    let (a_det, phi) = demodulate_period(&mut it.clone(), &model, samples).unwrap();
    let mut lock = LockIn::new(time_constant, period, a_det, phi);
    let (burn, periods) = (200, 30_000);
    let (mut a, mut ph) = (Vec::new(), Vec::new());
    for k in 0..burn + periods {
        let (ak, pk) = demodulate_period(&mut it, &model, samples).unwrap();
        lock.update(ak, pk);
        // as the scan does (`am_loop::scan_line`), each period from τ = 0, the stream going on
        let z = it.state().clone();
        it.reset(0.0, &z).unwrap();
        if k >= burn {
            a.push(lock.amplitude());
            ph.push(lock.phase());
        }
    }
    let var = |x: &[f64]| {
        let m = x.iter().sum::<f64>() / x.len() as f64;
        x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (x.len() - 1) as f64
    };
    let l2 = p.scales.length_m.powi(2);
    let simulated = [var(&a) * l2, var(&ph) * (a_det * a_det) * l2];
    // the linear response: ∫ S |G D|² df from the thermal spectrum
    let predicted = crate::analysis::lock_in_noise::tests::spectral_lock_in_variance(
        &p,
        &model,
        samples,
        time_constant,
        phi,
    );
    let beta = -(-period / time_constant).exp_m1();
    let rho = 1.0 - beta;
    let sigma = (2.0 * (1.0 + rho * rho) / ((1.0 - rho * rho) * periods as f64)).sqrt();
    for (name, (sim, pred)) in ["amplitude", "phase"]
        .iter()
        .zip(simulated.iter().zip(predicted))
    {
        let ratio = sim / pred;
        println!("{name}: σ = {:.4e} m (linear response {:.4e} m), ratio of variances {ratio:.4} ± {sigma:.4}", sim.sqrt(), pred.sqrt());
        assert!((ratio - 1.0).abs() < 5.0 * sigma, "{name}: {ratio}");
    }
}

/// The state at `end` of `model` from rest by the deterministic adaptive integrator (DOP853 at a
/// tolerance of 10⁻¹²).
fn deterministic(model: &CantileverModel, end: f64) -> DVector<f64> {
    let opts = IntegratorOptions {
        kind: crate::integrate::IntegratorKind::Adaptive,
        tolerance: 1e-12,
        ..IntegratorOptions::default()
    };
    let mut det = crate::integrate::build(model, opts, 0.0, &model.rest()).unwrap();
    crate::integrate::advance(det.as_mut(), end).unwrap();
    det.state().clone()
}

/// The state at `end` of `model` from rest by the stochastic step at k_BT → 0 (10⁻³⁰) on a grid
/// of a multiple of `steps` steps per period, and the switchings on the way.
fn vanishing(model: &CantileverModel, steps: usize, end: f64) -> (DVector<f64>, usize) {
    let opts = IntegratorOptions {
        steps_per_period: steps,
        ..IntegratorOptions::default()
    };
    let mut it = ThermalExact::new(model, &opts, ThermalForce::new(1e-30, 1)).unwrap();
    it.reset(0.0, &model.rest()).unwrap();
    let mut switchings = 0;
    while it.tau() < end {
        switchings += usize::from(it.step(end).unwrap().event.is_some());
    }
    (it.state().clone(), switchings)
}

/// The exponential Euler step of a nonlinear law against the deterministic adaptive integrator
/// (DOP853 at a tolerance of 10⁻¹²) as k_BT → 0: the paper's default lever tapping a Hertz
/// sample, the state after 4 periods from rest. With the force's rate in each piece the
/// deterministic part is second order (Cox & Matthews 2002): a 4× finer grid makes the error
/// 6–40× smaller (more than first order), below 2·10⁻⁵ of the state at the finer.
#[test]
fn the_hertz_step_converges_to_the_deterministic_orbit_as_the_temperature_vanishes() {
    let p = crate::params::Params {
        contact_law: crate::contact::ContactLaw::Hertz,
        ..crate::params::Params::default()
    };
    let model = CantileverModel::new(&p).unwrap();
    let end = 4.0 * model.period();
    let exact = deterministic(&model, end);
    let error = |steps: usize| {
        let (state, switchings) = vanishing(&model, steps, end);
        let err = (state - &exact).norm() / exact.norm();
        println!("{steps} steps per period at least: error {err:.3e}, {switchings} switchings");
        assert!(switchings >= 6, "{switchings} switchings: the lever taps");
        err
    };
    let (coarse, fine) = (error(1024), error(4096));
    let ratio = coarse / fine;
    assert!(
        (6.0..40.0).contains(&ratio),
        "{coarse:e} / {fine:e} = {ratio}"
    );
    assert!(fine < 2e-5, "{fine:e}");
}

/// The same under JKR (the default adhesion P̃ = 0.05, α4 of the paper's default sample), whose
/// contact forms at V_T = 0 and is left at V_T = |δ_f| > 0: the run carries the region through
/// the neck. The lever taps and every release is at |δ_f| (the neck's end, from JKR's closed
/// form, within the bridge's h/4096, not at V_T = 0), and the state after 4 periods from rest is the deterministic one
/// within 10⁻³ (measured 3·10⁻⁵ at 4 096 steps per period: the force's jump at the contact's
/// formation and its infinite rate at the neck's end lower the order there).
#[test]
fn the_jkr_step_carries_the_neck_as_the_temperature_vanishes() {
    let p = crate::params::Params {
        contact_law: crate::contact::ContactLaw::Jkr { adhesion: 0.05 },
        ..crate::params::Params::default()
    };
    let model = CantileverModel::new(&p).unwrap();
    let end = 4.0 * model.period();
    let exact = deterministic(&model, end);
    let opts = IntegratorOptions {
        steps_per_period: 4096,
        ..IntegratorOptions::default()
    };
    let mut it = ThermalExact::new(&model, &opts, ThermalForce::new(1e-30, 1)).unwrap();
    it.reset(0.0, &model.rest()).unwrap();
    // the neck's end δ_f = −3 q_f⁴, q_f³ = c/4, c = √(8P̃/(3α4)) (Johnson 1985 §5.5 in the
    // model's groups, `crate::contact::jkr`)
    let c = (8.0 * 0.05 / (3.0 * p.alpha4)).sqrt();
    let (release, mut releases) = (3.0 * (c / 4.0).powf(4.0 / 3.0), 0);
    while it.tau() < end {
        let step = it.step(end).unwrap();
        if step.event.is_some() && it.region() == Region::Free {
            let v = model.v_t(it.tau(), it.state());
            assert!(
                (v / release - 1.0).abs() < 1e-3,
                "released at V_T = {v} (|δ_f| = {release})"
            );
            releases += 1;
        }
    }
    let err = (it.state() - &exact).norm() / exact.norm();
    println!("{releases} releases at |δ_f| = {release:.4e}; error {err:.3e}");
    assert!(releases >= 3, "{releases} releases: the lever taps");
    assert!(err < 1e-3, "{err:e}");
}

/// A point-mass lever (40 N/m, Q = 2) pressed 2 nm into a Hertz sample (E = 1 GPa, ν = 0.3,
/// under a silicon tip of 10 nm, E_t = 130 GPa, ν_t = 0.27; K. L. Johnson, *Contact Mechanics*
/// (1985) §4.2: F = (4/3) E* R^{1/2} δ^{3/2}, 1/E* = (1 − ν²)/E + (1 − ν_t²)/E_t, contact
/// stiffness k_c = 2 E* (R δ)^{1/2}) rests at the indentation δ₀ where k (d₀ − δ₀) =
/// F(δ₀) (found here by bisection), and fluctuates about it as a harmonic oscillator of
/// stiffness k + k_c(δ₀): ⟨x⟩ = d₀ − δ₀ and Var x = k_BT/(k + k_c) (equipartition; σ ≈ 8 pm ≪
/// δ₀, so the linearisation's error is below 10⁻³). Sampled every period over 20 000 periods
/// within 5 standard errors (plus 2 % for the scheme's O(h) bias of the variance).
#[test]
fn a_lever_pressed_into_a_hertz_sample_fluctuates_with_the_contact_stiffness() {
    let (k, radius, e_modulus, nu, d0): (f64, f64, f64, f64, f64) = (40.0, 10e-9, 1e9, 0.3, 2e-9);
    let (e_tip, nu_tip) = (130e9, 0.27);
    let e_star = 1.0 / ((1.0 - nu * nu) / e_modulus + (1.0 - nu_tip * nu_tip) / e_tip);
    let text = format!(
        "model = \"point-mass\"\n[cantilever]\nspring_constant = {k}\n\
         resonance_frequency = 300e3\nquality_factor = 2\n[tip]\nradius = {radius}\n\
         youngs_modulus = {e_tip}\npoisson_ratio = {nu_tip}\n\
         [sample]\nlaw = \"hertz\"\nyoungs_modulus = {e_modulus}\npoisson_ratio = {nu}\n\
         z_c = {}\n[drive]\nfree_amplitude = 1e-9\nfrequency = 300e3\n",
        -d0
    );
    let mut p = Probe::parse(&text, "pressed").expect("probe");
    p.params.alpha2 = 0.0;
    let hertz = |d: f64| 4.0 / 3.0 * e_star * radius.sqrt() * d.powf(1.5);
    let (mut lo, mut hi) = (0.0, d0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if k * (d0 - mid) > hertz(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let delta0 = 0.5 * (lo + hi);
    let k_c = 2.0 * e_star * (radius * delta0).sqrt();
    let kt_si = BOLTZMANN * 295.0;
    let (want_mean, want_var) = (d0 - delta0, kt_si / (k + k_c));
    let model = CantileverModel::new(&p.params).unwrap();
    let opts = IntegratorOptions::default();
    let mut it = ThermalExact::new(&model, &opts, ThermalForce::new(kt_model(&p), 23))
        .unwrap()
        .holding(1);
    it.reset(0.0, &model.rest()).unwrap();
    let (mean, var, n) = pressed_tip(&mut it, &model, p.scales.length_m);
    let sigma = (2.0 / n).sqrt();
    println!(
        "δ₀ = {delta0:.4e} m, k_c = {k_c:.3} N/m: ⟨x⟩ {mean:.5e} against {want_mean:.5e}, \
         Var {var:.4e} against {want_var:.4e} (k_BT/k {:.4e}) ± {sigma:.4}",
        kt_si / k
    );
    assert!((mean - want_mean).abs() < 5.0 * (want_var / n).sqrt() + 1e-3 * want_mean);
    assert!(
        (var / want_var - 1.0).abs() < 5.0 * sigma + 0.02,
        "{var} against {want_var}"
    );
}

/// The tip's deflection (m, `length` metres per unit) of the point mass `model` pressed into
/// its sample, sampled every period over 20 000 periods after 100 by `it`, the tip staying in
/// contact: its mean, variance and the samples' count.
fn pressed_tip(it: &mut ThermalExact, model: &CantileverModel, length: f64) -> (f64, f64, f64) {
    let xs: Vec<f64> = (1..=20_000)
        .map(|j| {
            crate::integrate::advance(it, j as f64 * model.period()).unwrap();
            assert_eq!(it.region(), Region::Contact, "the tip stays on the sample");
            model.tip().dot(&it.state().rows(0, 1)) * length
        })
        .skip(100)
        .collect();
    let n = xs.len() as f64;
    let mean = xs.iter().sum::<f64>() / n;
    let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, var, n)
}

/// A multifrequency drive (a further tip force F̃ cos(p/q Ωτ + θ), `Params::drive_components`)
/// against the deterministic adaptive integrator (DOP853 at a tolerance of 10⁻¹²) as
/// k_BT → 0: the paper's default lever on its linear sample with a component near the second
/// mode (13/2 Ω: a grid over the common period of 2 drive periods) and one of
/// incommensurate-looking ratio 627/100 (a common period of 100 drive periods), the state after
/// 4 periods from rest. The exact step follows the primary's and each component's particular
/// solution: far from the sample the state is the deterministic one within 10⁻⁹ of it (the
/// integrators' tolerance; measured 7·10⁻¹¹); tapping, within 10⁻⁴ (measured 5.9·10⁻⁵ and
/// 1.7·10⁻⁵; 3.7·10⁻⁵ without the components: the switchings located to h/4096 on the bridge),
/// while the components move it by more than 10⁻² (the run without them).
#[test]
fn a_multifrequency_drive_is_the_deterministic_run_as_the_temperature_vanishes() {
    use crate::params::DriveComponent;
    for (ratio, force) in [([13, 2], 0.3), ([627, 100], 0.2)] {
        for alpha5 in [100.0, crate::params::Params::default().alpha5] {
            let mut p = crate::params::Params {
                alpha5,
                ..crate::params::Params::default()
            };
            let single = CantileverModel::new(&p).unwrap();
            p.drive_components[0] = Some(DriveComponent {
                force,
                ratio,
                phase: 0.4,
            });
            let model = CantileverModel::new(&p).unwrap();
            let end = 4.0 * std::f64::consts::TAU / p.omega;
            let exact = deterministic(&model, end);
            let moved = (deterministic(&single, end) - &exact).norm() / exact.norm();
            let (state, switchings) = vanishing(&model, 1, end);
            let err = (state - &exact).norm() / exact.norm();
            println!(
                "{ratio:?}, α5 = {alpha5}: error {err:.3e}, {switchings} switchings, the \
                 components move the state by {moved:.3e}"
            );
            assert!(moved > 1e-2, "{ratio:?}: {moved:e}");
            if alpha5 == 100.0 {
                assert_eq!(switchings, 0);
                assert!(err < 1e-9, "{ratio:?}, far: {err:e}");
            } else {
                assert!(
                    switchings >= 4,
                    "{ratio:?}: {switchings} switchings: the lever taps"
                );
                assert!(err < 1e-4, "{ratio:?}, tapping: {err:e}");
            }
        }
    }
}

/// SLS (the standard linear solid, its dashpot's extension u a state of its own) against the
/// deterministic adaptive integrator (DOP853 at a tolerance of 10⁻¹²) as k_BT → 0: the paper's
/// default lever tapping an SLS sample with surface memory (κ = 20, α6 = 20: a relaxation time
/// of 1 in contact, a recovery time of 2 free, a third of the period), the state after 4
/// periods from rest; the same lever far from it; and a one-mode lever on a stiff Maxwell arm
/// (κ = 20 000, the contact's oscillation 140 times the lever's). The step is exact in each
/// region over the model's own affine system in 2N + 1 dimensions, about its particular
/// solution, and its switchings, where V_T + s(u) changes sign (the recovering surface s(u),
/// `crate::contact::Zener::surface`), are located on the bridge: tapping, the state is the
/// deterministic one within 10⁻⁴ (the bridge's h/4096, as under the linear law; measured
/// 7·10⁻⁹ and 3·10⁻¹¹); far, within 10⁻⁹ (the integrators' tolerance), with u relaxing to 0.
/// The grid resolves the instantaneous stiffness α4 + κ (`grid_model`): on the lever's own grid
/// the stiff arm's contacts fell between the bridge's test points and the run diverged.
#[test]
fn an_sls_tap_is_the_deterministic_run_as_the_temperature_vanishes() {
    let default = crate::params::Params::default();
    for (alpha5, maxwell_stiffness, modes) in [
        (100.0, 20.0, default.modes),
        (default.alpha5, 20.0, default.modes),
        (default.alpha5, 20_000.0, 1),
    ] {
        let p = crate::params::Params {
            contact_law: crate::contact::ContactLaw::Sls { maxwell_stiffness },
            alpha5,
            alpha6: 20.0,
            modes,
            ..default
        };
        let model = CantileverModel::new(&p).unwrap();
        let end = 4.0 * model.period();
        let exact = deterministic(&model, end);
        let (state, switchings) = vanishing(&model, 1, end);
        let err = (state - &exact).norm() / exact.norm();
        let u = exact[2 * p.modes];
        println!("α5 = {alpha5}, κ = {maxwell_stiffness}: error {err:.3e}, {switchings} switchings, u = {u:.4e}");
        if alpha5 == 100.0 {
            assert_eq!(switchings, 0);
            assert!(err < 1e-9, "far: {err:e}");
        } else {
            assert!(switchings >= 6, "{switchings} switchings: the lever taps");
            assert!(u.abs() > 1e-4, "the dashpot moves");
            assert!(err < 1e-4, "tapping: {err:e}");
        }
    }
}

/// A point-mass lever (40 N/m, Q = 2) pressed d₀ = 2 nm into an SLS sample (relaxed spring
/// k_r = 20 N/m, Maxwell arm k_m = 40 N/m with τ_r = 0.5 µs, a sixth of the lever's period),
/// undriven. The lever's and the dashpot's thermal forces (each 2 k_BT times its damping,
/// the fluctuation–dissipation theorem) hold the Boltzmann distribution of the energy
/// ½k x² + ½k_r δ² + ½k_m (δ − u)², δ = d₀ − x the indentation: integrated over the dashpot's
/// extension u it is that of ½(k + k_r)x² less a constant, so ⟨x⟩ = k_r d₀/(k + k_r) and
/// Var x = k_BT/(k + k_r), the relaxed stiffness's (while the tap's instantaneous stiffness
/// is k + k_r + k_m; without the dashpot's own noise the variance falls short). Sampled every
/// period over 20 000 periods within 5 standard errors.
#[test]
fn a_lever_pressed_into_an_sls_sample_fluctuates_with_its_relaxed_stiffness() {
    let (k, k_r, d0) = (40.0_f64, 20.0_f64, 2e-9_f64);
    let text = format!(
        "model = \"point-mass\"\n[cantilever]\nspring_constant = {k}\n\
         resonance_frequency = 300e3\nquality_factor = 2\n[tip]\nradius = 10e-9\n\
         [sample]\nlaw = \"sls\"\nstiffness = {k_r}\nmaxwell_stiffness = 40.0\n\
         relaxation_time = 0.5e-6\nz_c = {}\n[drive]\nfree_amplitude = 1e-9\n\
         frequency = 300e3\n",
        -d0
    );
    let mut p = Probe::parse(&text, "pressed").expect("probe");
    p.params.alpha2 = 0.0;
    let kt_si = BOLTZMANN * 295.0;
    let (want_mean, want_var) = (k_r * d0 / (k + k_r), kt_si / (k + k_r));
    let model = CantileverModel::new(&p.params).unwrap();
    let mut it = ThermalExact::new(
        &model,
        &IntegratorOptions::default(),
        ThermalForce::new(kt_model(&p), 29),
    )
    .unwrap()
    .holding(1);
    // from the relaxed equilibrium in contact (u = δ)
    let mut z0 = DVector::zeros(3);
    z0[0] = want_mean / (p.scales.length_m * model.tip()[0]);
    z0[2] = (d0 - want_mean) / p.scales.length_m;
    it.reset_in(0.0, &z0, Region::Contact).unwrap();
    let (mean, var, n) = pressed_tip(&mut it, &model, p.scales.length_m);
    let sigma = (2.0 / n).sqrt();
    println!(
        "⟨x⟩ {mean:.5e} against {want_mean:.5e}, Var {var:.4e} against {want_var:.4e} \
         (k_BT/(k + k_r + k_m) {:.4e}) ± {sigma:.4}",
        kt_si / (k + k_r + 40.0)
    );
    assert!((mean - want_mean).abs() < 5.0 * (want_var / n).sqrt());
    assert!(
        (var / want_var - 1.0).abs() < 5.0 * sigma,
        "{var} against {want_var}"
    );
}

/// The impact law's step as k_BT → 0 against the deterministic adaptive integrator (DOP853 with
/// its impact map and sticking at a tolerance of 10⁻¹²): the paper's lever tapping a rigid
/// sample, the state after 4 drive periods from rest, within 10⁻⁴ at the default grid
/// (measured 8.6·10⁻⁶ and 4.8·10⁻⁵ for one mode at r = 1/2 and 0.8; 1.0·10⁻⁵ for three modes
/// at r = 0, which stick and are released; 3.5·10⁻⁷ for one mode under a further drive
/// component at 13/2 Ω, whose force the sticking constraint takes itself). Where the tip's
/// motion is faster than the grid (three modes under that component; two modes at r = 0.3,
/// chattering into sticking with the second mode ringing after each impact) the default grid
/// misses a grazing impact between its test points at T → 0 (V̇_T = −0.005), and at 256 steps
/// per period the run is within 10⁻⁵ (measured 8.2·10⁻⁷ and 4.1·10⁻⁷).
#[test]
fn an_impacting_tap_is_the_deterministic_run_as_the_temperature_vanishes() {
    let default = crate::params::Params::default();
    let component = crate::params::DriveComponent {
        force: 0.3,
        ratio: [13, 2],
        phase: 0.4,
    };
    for (restitution, modes, steps, tolerance, further) in [
        (0.5, 1, 1, 1e-4, None),
        (0.8, 1, 1, 1e-4, None),
        (0.0, default.modes, 1, 1e-4, None),
        (0.0, default.modes, 256, 1e-5, Some(component)),
        (0.0, 1, 1, 1e-4, Some(component)),
        (0.3, 2, 256, 1e-5, None),
    ] {
        let mut p = crate::params::Params {
            contact_law: crate::contact::ContactLaw::Impact { restitution },
            modes,
            ..default
        };
        p.drive_components[0] = further;
        let model = CantileverModel::new(&p).unwrap();
        let end = 4.0 * std::f64::consts::TAU / p.omega;
        let exact = deterministic(&model, end);
        let (state, events) = vanishing(&model, steps, end);
        let err = (state - &exact).norm() / exact.norm();
        println!(
            "r = {restitution}, {modes} modes, {steps} steps, {further:?}: error {err:.3e}, \
             {events} events"
        );
        assert!(events >= 6, "{events} events: the lever taps");
        assert!(err < tolerance, "r = {restitution}, {modes} modes: {err:e}");
    }
}

/// A point-mass lever (40 N/m, 300 kHz, Q = 2) at rest d = σ/2 above a rigid sample
/// (σ = (k_BT/k)^{1/2}, the free tip's thermal deflection), undriven, sampled every period
/// over 20 000 periods: its deflections x, rates ẋ and its impacts.
fn walled(restitution: f64, seed: u64) -> (Vec<(f64, f64)>, f64, f64, f64, f64) {
    let (k, f0, q) = (40.0_f64, 300e3_f64, 2.0_f64);
    let kt_si = BOLTZMANN * 295.0;
    let d = 0.5 * (kt_si / k).sqrt();
    let text = format!(
        "model = \"point-mass\"\n[cantilever]\nspring_constant = {k}\n\
         resonance_frequency = {f0}\nquality_factor = {q}\n[tip]\nradius = 10e-9\n\
         [sample]\nlaw = \"impact\"\nrestitution = {restitution}\nz_c = {d}\n\
         [drive]\nfree_amplitude = 1e-9\nfrequency = {f0}\n"
    );
    let mut p = Probe::parse(&text, "walled").expect("probe");
    p.params.alpha2 = 0.0;
    let model = CantileverModel::new(&p.params).unwrap();
    let opts = IntegratorOptions::default();
    let force = ThermalForce::new(kt_model(&p), seed);
    let mut it = ThermalExact::new(&model, &opts, force).unwrap().holding(1);
    it.reset(0.0, &model.rest()).unwrap();
    let (length, time) = (p.scales.length_m, p.scales.time_s);
    let (mut samples, mut loss, mut impacts) = (Vec::new(), 0.0, 0);
    let mass = k / (std::f64::consts::TAU * f0).powi(2);
    for j in 1..=20_100 {
        let end = j as f64 * model.period();
        while it.tau() < end {
            if let Some(e) = it.step(end).unwrap().event {
                assert_eq!(e.kind, EventKind::Impact, "the tip never sticks here");
                let v = e.v_t_dot * length / time;
                if j > 100 {
                    loss += 0.5 * mass * v * v * (1.0 - restitution * restitution);
                    impacts += 1;
                }
            }
        }
        if j > 100 {
            let n = model.modes();
            let z = it.state();
            let x = model.tip().dot(&z.rows(0, n)) * length;
            samples.push((x, model.tip().dot(&z.rows(n, n)) * length / time));
        }
    }
    let duration = 20_000.0 / f0;
    let gamma = std::f64::consts::TAU * f0 / q;
    println!("r = {restitution}: {impacts} impacts");
    (samples, d, loss / duration, gamma, mass)
}

/// A rigid sample under a thermally driven lever (module docs' impact law; [`walled`]). With
/// r = 1 the reflection keeps the energy and phase-space volume, so the stationary distribution is
/// Boltzmann's cut at the sample (statistical mechanics of a hard wall): x > −d with
/// ⟨x⟩ = σ λ, Var x = σ²(1 − (d/σ) λ − λ²), λ = φ(d/σ)/Φ(d/σ) (the normal distribution
/// truncated below −d), and m⟨ẋ²⟩ = k_BT; each within 5 standard errors. With r = 1/2 the
/// impacts dissipate ½ m v²(1 − r²) each, and in the stationary state that loss per unit time
/// is the power the thermal force puts in beyond the damping's, γ(k_BT − m⟨ẋ²⟩) (d⟨E⟩/dt of
/// m ẍ = −kx − cẋ + ξ, ⟨ξξ⟩ = 2ck_BT δ, γ = c/m): within 5 standard errors of ⟨ẋ²⟩.
#[test]
fn a_lever_over_a_rigid_sample_holds_the_hard_walls_statistics() {
    let kt = BOLTZMANN * 295.0;
    let (xs, d, _, _, mass) = walled(1.0, 3);
    let n = xs.len() as f64;
    let sigma = (kt / 40.0).sqrt();
    let a = d / sigma;
    let pdf = (-0.5 * a * a).exp() / std::f64::consts::TAU.sqrt();
    // Φ(a) = 1/2 + ∫₀^a φ, by 24-point Gauss–Legendre quadrature (exact to round-off for
    // a ≤ 1)
    let rule = gauss_quad::legendre::GaussLegendre::new(std::num::NonZeroUsize::new(24).unwrap());
    let cdf = 0.5 + rule.integrate(0.0, a, |u| pdf * (0.5 * (a * a - u * u)).exp());
    let lam = pdf / cdf;
    let (want_mean, want_var) = (sigma * lam, sigma * sigma * (1.0 - a * lam - lam * lam));
    let mean = xs.iter().map(|s| s.0).sum::<f64>() / n;
    let var = xs.iter().map(|s| (s.0 - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let v2 = xs.iter().map(|s| s.1 * s.1).sum::<f64>() / n;
    println!(
        "⟨x⟩ {:.4} σ against {:.4} σ, Var {:.4} σ² against {:.4} σ², m⟨ẋ²⟩/k_BT {:.4}; min x {:.4} σ",
        mean / sigma,
        want_mean / sigma,
        var / sigma / sigma,
        want_var / sigma / sigma,
        mass * v2 / kt,
        xs.iter().map(|s| s.0).fold(f64::INFINITY, f64::min) / sigma
    );
    assert!((mean - want_mean).abs() < 5.0 * (want_var / n).sqrt());
    assert!((var / want_var - 1.0).abs() < 5.0 * (2.0 / n).sqrt());
    assert!((mass * v2 / kt - 1.0).abs() < 5.0 * (2.0 / n).sqrt());
    let (xs, _, loss_rate, gamma, mass) = walled(0.5, 4);
    let v2 = xs.iter().map(|s| s.1 * s.1).sum::<f64>() / xs.len() as f64;
    let input = gamma * (kt - mass * v2);
    let err = gamma * mass * v2 * (2.0 / xs.len() as f64).sqrt();
    println!("loss {loss_rate:.4e} W against γ(k_BT − m⟨ẋ²⟩) {input:.4e} ± {err:.1e} W");
    assert!((loss_rate - input).abs() < 5.0 * err);
}

/// The beam of examples/probe-water-beam.toml (three modes in water) pressed 50 nm into a rigid
/// sample (r = 1/2), undriven: the tip sticks and stays held, V_T = 0, while the thermal force
/// moves the rest of the beam. The constraint takes the force's part at the tip
/// (`state_diffusion`), so the modal coordinates a hold equipartition conditioned on
/// φᵀa fixed: Cov a = P − Pφ(φᵀPφ)⁻¹φᵀP, P = k_BT K⁻¹ (the Gaussian's conditional
/// covariance). Sampled every period over 20 000 periods, each mode's variance within 5
/// standard errors.
#[test]
fn a_beam_held_on_a_rigid_sample_fluctuates_as_equipartition_pinned_at_its_tip() {
    let p = water("law = \"impact\"\nrestitution = 0.5\nz_c = -50e-9", 0.0);
    let model = CantileverModel::new(&p.params).unwrap();
    let kt = kt_model(&p);
    let force = ThermalForce::new(kt, 11);
    let mut it = ThermalExact::new(&model, &IntegratorOptions::default(), force)
        .unwrap()
        .holding(1);
    // from the static shape held on the surface: a = K⁻¹φ s with V_T = 0
    let n = model.modes();
    let k = &model.galerkin().region(Region::Free).stiffness;
    let k_inv_phi = k.clone().try_inverse().unwrap() * model.tip();
    let mut z0 = DVector::zeros(2 * n);
    let v0 = model.v_t(0.0, &z0);
    z0.rows_mut(0, n)
        .copy_from(&(&k_inv_phi * (-v0 / model.tip().dot(&k_inv_phi))));
    assert!(
        model.guard_value(Region::Contact, 0.0, z0.as_slice()) > 0.0,
        "λ > 0: held"
    );
    it.reset_in(0.0, &z0, Region::Contact).unwrap();
    let samples: Vec<DVector<f64>> = (1..=20_100)
        .map(|j| {
            crate::integrate::advance(&mut it, j as f64 * model.period()).unwrap();
            assert_eq!(it.region(), Region::Contact, "the tip stays held");
            let v = model.v_t(it.tau(), it.state());
            assert!(v.abs() < 1e-9, "V_T = {v:e}");
            it.state().rows(0, n).into_owned()
        })
        .skip(100)
        .collect();
    let count = samples.len() as f64;
    let mean = samples.iter().sum::<DVector<f64>>() / count;
    let p_cov = k.clone().try_inverse().unwrap() * kt;
    let phi = model.tip();
    let pphi = &p_cov * phi;
    let want = &p_cov - &pphi * pphi.transpose() / phi.dot(&pphi);
    for m in 0..n {
        let var = samples
            .iter()
            .map(|a| (a[m] - mean[m]).powi(2))
            .sum::<f64>()
            / (count - 1.0);
        let sigma = (2.0 / count).sqrt();
        println!(
            "mode {}: Var {var:.4e} against {:.4e} (free {:.4e}) ± {sigma:.3}",
            m + 1,
            want[(m, m)],
            p_cov[(m, m)]
        );
        assert!(
            (var / want[(m, m)] - 1.0).abs() < 5.0 * sigma,
            "mode {}",
            m + 1
        );
    }
}

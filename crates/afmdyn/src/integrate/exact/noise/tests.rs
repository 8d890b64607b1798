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
    let text = include_str!("../../../../../../examples/probe-water-beam.toml");
    let (head, rest) = text.split_at(text.find("[sample]").unwrap());
    let tail = &rest[rest.find("[drive]").unwrap()..];
    let drive = if a0 > 0.0 { a0 } else { 1e-9 };
    let tail = tail.replace(
        "free_amplitude = 10e-9",
        &format!("free_amplitude = {drive}"),
    );
    let sample = format!("[sample]\nlaw = \"linear\"\nstiffness = 1.0\nz_c = {z_c}\n");
    let mut p = Probe::parse(&format!("{head}{sample}{tail}"), "water").expect("probe");
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
    let zp = |t: f64| it.zp(Region::Free, (it.model().omega() * t).sin_cos());
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
                - it.zp(Region::Free, (it.model().omega() * t).sin_cos());
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
                sc(w[0].0),
                &DVector::from_column_slice(&w[0].1),
            ) > 0.0)
                != (it.gap(
                    Region::Free,
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

/// `simulate`'s `temperature`: refused without a probe (naming `temperature`) and for a
/// nonlinear law (naming the law); with the linear probe the same seed records the same run
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
    let dmt = Probe::parse(
        include_str!("../../../../../../examples/probe-water-beam.toml"),
        "w",
    )
    .unwrap();
    let dmt_model = CantileverModel::new(&dmt.params).unwrap();
    match request(Some(295.0), 0).record_whole(&dmt_model, Some(&dmt), &span) {
        Err(SimError::Unsupported { law, .. }) => assert_eq!(law, "dmt"),
        other => panic!("{other:?}"),
    }
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
        let mut it = ThermalExact::new(&model, &opts, ThermalForce::new(kt, 17)).unwrap();
        let runs = 3000;
        let mut sum = 0.0;
        for _ in 0..runs {
            it.reset(0.0, &model.rest()).unwrap();
            crate::integrate::advance(&mut it, t).unwrap();
            let dz = it.state() - it.zp(Region::Free, (model.omega() * t).sin_cos());
            sum += model.tip().dot(&dz.rows(0, 1)).powi(2);
        }
        let got = sum / runs as f64;
        let sigma = (2.0 / runs as f64).sqrt();
        println!(
            "Q = {q}: ⟨x²⟩ {got:.4e} against {want:.4e} ({:.4} of k_BT/k)",
            want * k / kt
        );
        assert!(
            (got / want - 1.0).abs() < 5.0 * sigma,
            "Q = {q}: {got} against {want}"
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
    use std::f64::consts::TAU;
    let p = water_linear(1e-6, 5e-9);
    let model = CantileverModel::new(&p.params).unwrap();
    let samples = 32;
    let opts = IntegratorOptions {
        steps_per_period: holding_samples(1, samples),
        ..IntegratorOptions::default()
    };
    let mut it = ThermalExact::new(&model, &opts, ThermalForce::new(kt_model(&p), 5)).unwrap();
    let z0 = it.zp(Region::Free, (0.0, 1.0));
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
    // the linear response: ∫ S |G D|² df on a grid that resolves G's peaks (width β/(2πT))
    let t_s = period * p.scales.time_s;
    let f_d = 1.0 / t_s;
    let beta = -(-period / time_constant).exp_m1();
    let df = 2e-4 * f_d;
    let f: Vec<f64> = (1..200_000).map(|i| i as f64 * df).collect();
    let s = thermal_spectrum(&p.params, units(&p), 295.0, 1.0, &f, &Progress::default())
        .unwrap()
        .deflection;
    let psi = model.params().drive_phase();
    let predicted = [0, 1].map(|part| {
        f.iter()
            .zip(&s)
            .map(|(&f, &s)| {
                let x = TAU * f * t_s;
                let g2 = beta * beta / (1.0 + (1.0 - beta).powi(2) - 2.0 * (1.0 - beta) * x.cos());
                let (mut re, mut im) = (0.0, 0.0);
                for j in 1..=samples {
                    let u = j as f64 / samples as f64;
                    let theta = TAU * u + psi - phi;
                    let c = if part == 0 { theta.sin() } else { theta.cos() };
                    re += c * (x * u).cos();
                    im += c * (x * u).sin();
                }
                let d2 = (2.0 / samples as f64).powi(2) * (re * re + im * im);
                s * g2 * d2 * df
            })
            .sum::<f64>()
    });
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

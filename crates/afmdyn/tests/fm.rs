//! FM-AFM at constant amplitude ([`afmdyn::analysis::fm`]) against stated sources: Giessibl's
//! first-order frequency shift (Phys. Rev. B 56, 16010 (1997)) and its small-amplitude limit
//! −f0 F′/(2k), the period energy balance of the point mass, and the Sader–Jarvis round trip
//! (Appl. Phys. Lett. 84, 1801 (2004)).

use afmdyn::analysis::fm::{fm_curve, FmSpec};
use afmdyn::analysis::progress::Progress;
use afmdyn::probe::Probe;
use std::f64::consts::PI;

/// A stiff lever in UHV-like conditions over a van der Waals sample: k = 40 N/m, f0 = 300 kHz,
/// Q = 10⁴, R = 10 nm, H = 6.6e-20 J (no contact damping), A = 10 nm.
const PROBE: &str = r#"
model = "point-mass"
[cantilever]
spring_constant = 40.0
resonance_frequency = 300e3
quality_factor = 1e4
[tip]
radius = 10e-9
youngs_modulus = 130e9
poisson_ratio = 0.27
[sample]
law = "dmt"
youngs_modulus = 4e9
poisson_ratio = 0.33
hamaker = 6.6e-20
intermolecular_distance = 0.165e-9
viscosity = 0.0
z_c = 20e-9
[drive]
free_amplitude = 10e-9
frequency = 300e3
"#;

/// The gap values α5 of the rest distances `z_c` (m) under `probe`.
fn gaps(probe: &Probe, z_c: &[f64]) -> Vec<f64> {
    z_c.iter()
        .map(|z| {
            probe
                .params
                .alpha5_for_rest_distance(z / probe.scales.length_m)
        })
        .collect()
}

/// The van der Waals force of a sphere over a plane, −HR/(6d²) (N), d in m.
fn vdw(d: f64) -> f64 {
    -6.6e-20 * 10e-9 / (6.0 * d * d)
}

/// Giessibl's first-order shift (Hz) of an oscillation of amplitude `a` (m) about the centre
/// `centre` (m): −(f0/(π k A)) ∫₋₁¹ F(centre + A u) u/√(1−u²) du, here by the substitution
/// u = cos θ and a 4000-point midpoint rule in θ (independent of the library's quadrature).
fn giessibl(centre: f64, a: f64, k: f64, f0: f64) -> f64 {
    let n = 4000;
    let mut s = 0.0;
    for i in 0..n {
        let th = PI * (i as f64 + 0.5) / n as f64;
        let u = th.cos();
        s += vdw(centre + a * u) * u;
    }
    let integral = s * PI / n as f64;
    -f0 / (PI * k * a) * integral
}

#[test]
fn fm_shift_matches_giessibl_first_order_formula() {
    let probe = Probe::parse(PROBE, "test").unwrap();
    let g0 = probe.scales.length_m;
    // z_c from 20 nm to 10.8 nm: lower turning points from 10 nm to 0.8 nm
    let z_c: Vec<f64> = (0..24).map(|i| 20e-9 - i as f64 * 0.4e-9).collect();
    let values = gaps(&probe, &z_c);
    let spec = FmSpec::new(probe.params, values, 1.0);
    let curve = fm_curve(&spec, &Progress::new()).unwrap();
    assert!(curve.unreached.is_none(), "{:?}", curve.unreached);
    assert_eq!(curve.points.len(), z_c.len());
    // the point mass: ω0 = 1, the free lag at resonance 90°, the free excitation A/Q
    assert!((curve.reference.omega - 1.0).abs() < 1e-12);
    assert!((curve.reference.phase - PI / 2.0).abs() < 1e-12);
    assert!((curve.reference.excitation - probe.params.alpha3).abs() < 1e-12);
    let (k, f0) = (40.0, 300e3);
    let a = g0;
    for (p, &zc) in curve.points.iter().zip(&z_c) {
        let df = probe.scales.frequency_hz(p.omega - curve.reference.omega);
        // the centre of the oscillation: z_c plus the static deflection
        let centre = zc + p.observables.mean_deflection * g0;
        let d_min = p.observables.min_distance * g0;
        let expected = giessibl(centre, a, k, f0);
        // first-order error O(max|F|/(kA))
        let bound = vdw(d_min).abs() / (k * a);
        let rel = (df - expected).abs() / expected.abs();
        assert!(rel <= 3.0 * bound + 1e-6, "z_c {zc}: {df} vs {expected}");
        assert!(p.stable && p.loop_residual <= 1e-6);
    }
}

fn beam_probe() -> Probe {
    let text = PROBE.replace("model = \"point-mass\"\n", "model = \"beam\"\nmodes = 3\n");
    Probe::parse(&text, "beam").unwrap()
}

/// The Galerkin beam (N = 3, base drive) with the same calibrated k, f0 and Q: its first mode
/// follows Giessibl's formula with the calibrated k (the higher modes, 6× and 17× stiffer in
/// frequency, take part only at second order).
#[test]
fn beam_fm_shift_matches_giessibl_with_the_first_modes_stiffness() {
    let probe = beam_probe();
    let g0 = probe.scales.length_m;
    let z_c: Vec<f64> = (0..12).map(|i| 20e-9 - i as f64 * 0.8e-9).collect();
    let values = gaps(&probe, &z_c);
    let curve = fm_curve(&FmSpec::new(probe.params, values, 1.0), &Progress::new()).unwrap();
    assert_eq!(curve.points.len(), z_c.len());
    // the free base-driven beam's lag at its first natural frequency is not exactly 90°
    assert!((curve.reference.phase - PI / 2.0).abs() < 1e-3);
    let (k, f0) = (
        probe.calibration.spring_constant,
        probe.calibration.resonance_frequency,
    );
    for (p, &zc) in curve.points.iter().zip(&z_c) {
        let df = probe.scales.frequency_hz(p.omega - curve.reference.omega);
        let centre = zc + p.observables.mean_deflection * g0;
        let d_min = p.observables.min_distance * g0;
        let expected = giessibl(centre, g0, k, f0);
        let bound = vdw(d_min).abs() / (k * g0);
        let rel = (df - expected).abs() / expected.abs();
        assert!(rel <= 3.0 * bound + 1e-6, "z_c {zc}: {df} vs {expected}");
        assert!(p.stable);
        assert!(p.loop_residual < 1e-7);
    }
}

/// Small amplitude: Δf → −f0 F′(d)/(2k) (the force gradient acts as a spring; Giessibl,
/// Rev. Mod. Phys. 75, 949 (2003), eq. 15), with relative corrections O((A/d)²).
#[test]
fn small_amplitude_shift_is_the_force_gradient() {
    let probe = Probe::parse(PROBE, "test").unwrap();
    let g0 = probe.scales.length_m;
    let a = 0.05e-9;
    let z_c: Vec<f64> = vec![4e-9, 3e-9, 2e-9];
    let values = gaps(&probe, &z_c);
    let curve = fm_curve(&FmSpec::new(probe.params, values, a / g0), &Progress::new()).unwrap();
    let (k, f0) = (40.0, 300e3);
    for (p, &zc) in curve.points.iter().zip(&z_c) {
        let df = probe.scales.frequency_hz(p.omega - curve.reference.omega);
        let d = zc + p.observables.mean_deflection * g0;
        // F = −HR/(6d²): F′ = HR/(3d³)
        let gradient = 6.6e-20 * 10e-9 / (3.0 * d * d * d);
        let expected = -f0 * gradient / (2.0 * k);
        let rel = (df - expected).abs() / expected.abs();
        assert!(
            rel < 2.0 * (a / d).powi(2) + 1e-6,
            "z_c {zc}: {df} vs {expected} ({rel:e})"
        );
    }
}

/// Dissipation: the excitation the controller needs is the free one plus what the sample and
/// the higher harmonics take. For the point mass at φ₁ = 90° the period balance is
/// π α2 A = (π/Q) Ω (A² + Σ n²Aₙ²) + E_dis (module docs of `observables`), here with the
/// tip–sample energy E_dis of a viscous DMT contact at Q = 10⁴, to 1e-8 of the drive's
/// energy. The curve crosses the contact edge, where the nested solve stalls at this Q (the
/// augmented Newton's case).
#[test]
fn excitation_grows_by_the_energy_dissipated() {
    let text = PROBE.replace("viscosity = 0.0", "viscosity = 50.0");
    let probe = Probe::parse(&text, "viscous").unwrap();
    let z_c: Vec<f64> = (0..30).map(|i| 11e-9 - i as f64 * 0.05e-9).collect();
    let values = gaps(&probe, &z_c);
    let curve = fm_curve(&FmSpec::new(probe.params, values, 1.0), &Progress::new()).unwrap();
    assert!(curve.unreached.is_none(), "{:?}", curve.unreached);
    let q_inv = probe.params.alpha3;
    let mut dissipated = 0.0f64;
    for p in &curve.points {
        let o = &p.observables;
        let drive = PI * p.alpha2 * o.amplitude * o.phase.sin();
        let damping = PI * q_inv * p.omega * (o.amplitude.powi(2) + o.higher_n2_sq);
        assert!(
            (drive - damping - o.energy_dissipated).abs() <= 1e-8 * drive,
            "{drive} vs {damping} + {}",
            o.energy_dissipated
        );
        // the excitation relative to the free one (A/Q at ω0)
        let relative = p.alpha2 / curve.reference.excitation;
        let expected = p.omega * (1.0 + o.higher_n2_sq / o.amplitude.powi(2))
            + o.energy_dissipated / (PI * q_inv * o.amplitude.powi(2));
        assert!(
            (relative - expected).abs() < 1e-7,
            "{relative} vs {expected}"
        );
        dissipated = dissipated.max(o.energy_dissipated);
    }
    // the curve reaches the contact, where the viscous sample takes energy
    assert!(dissipated > 1e-5, "E_dis up to {dissipated}");
}

/// Bad requests are refused naming the field.
#[test]
fn bad_spec_is_refused_naming_the_field() {
    let probe = Probe::parse(PROBE, "test").unwrap();
    let one = vec![probe.params.alpha5];
    for (spec, field) in [
        (FmSpec::new(probe.params, one.clone(), 0.0), "amplitude"),
        (FmSpec::new(probe.params, vec![], 1.0), "values"),
        (FmSpec::new(probe.params, vec![f64::NAN], 1.0), "z_c"),
        (
            FmSpec {
                mode: 2,
                ..FmSpec::new(probe.params, one.clone(), 1.0)
            },
            "mode",
        ),
    ] {
        let e = fm_curve(&spec, &Progress::new()).unwrap_err().to_string();
        assert!(e.contains(field), "{e}");
    }
}

/// At Q = 10⁴ the default range ends where the lower turning point reaches the DMT contact
/// edge, whose force gradient jumps, while M − I is nearly singular (multipliers within π/Q of
/// 1). Every value is reached (the nested solve falls back to the augmented Newton), the loop
/// conditions met to 1e-6, the shift monotonic, every orbit stable under the locked drive.
#[test]
fn high_q_curve_reaches_the_contact_edge() {
    let probe = Probe::parse(PROBE, "test").unwrap();
    let a0 = 0.165e-9;
    let z_c: Vec<f64> = (0..100)
        .map(|i| 20e-9 + a0 - i as f64 * 10e-9 / 99.0)
        .collect();
    let values = gaps(&probe, &z_c);
    let curve = fm_curve(&FmSpec::new(probe.params, values, 1.0), &Progress::new()).unwrap();
    assert!(curve.unreached.is_none(), "{:?}", curve.unreached);
    assert_eq!(curve.points.len(), 100);
    assert!(curve.points.iter().all(|p| p.loop_residual <= 1e-6));
    assert!(curve.points.windows(2).all(|w| w[1].omega < w[0].omega));
    assert!(curve.points.iter().all(|p| p.stable));
}

/// The time-domain loop (`analysis::fm_loop`: the cantilever integrated cycle after cycle, a
/// PLL and an amplitude controller correcting the drive once per cycle) settles on the exact
/// steady state: the same frequency shift within what the settling tolerance allows.
#[test]
fn the_time_domain_loop_settles_on_the_exact_steady_state() {
    use afmdyn::analysis::fm::LoopSpec;
    use afmdyn::analysis::fm_loop::fm_loop;
    let text = PROBE.replace("quality_factor = 1e4", "quality_factor = 400");
    let probe = Probe::parse(&text, "q400").unwrap();
    let z_c: Vec<f64> = (0..5).map(|i| 14e-9 - i as f64 * 0.8e-9).collect();
    let values = gaps(&probe, &z_c);
    let spec = FmSpec::new(probe.params, values, 1.0);
    let exact = fm_curve(&spec, &Progress::new()).unwrap();
    let looped = fm_loop(&spec, &LoopSpec::new(400.0), &Progress::new()).unwrap();
    for (e, l) in exact.points.iter().zip(&looped) {
        assert!(l.settled);
        assert!((e.alpha2 - l.alpha2).abs() <= 1e-5 * e.alpha2);
        let (de, dl) = (
            e.omega - exact.reference.omega,
            l.omega - exact.reference.omega,
        );
        assert!((de - dl).abs() <= 1e-3 * de.abs(), "{de} vs {dl}");
    }
}

/// The beam's second mode tracked (`mode = 2`, as the second channel of bimodal AM-FM
/// imaging): Giessibl's formula holds with that mode's frequency f₂ and its stiffness at the
/// tip k̃₂ (Melcher, Hu & Raman 2007; 39.3 k for a uniform beam, (β₂/β₁)⁴).
#[test]
fn the_second_mode_follows_giessibl_with_its_own_stiffness() {
    let probe = beam_probe();
    let g0 = probe.scales.length_m;
    let z_c: Vec<f64> = (0..8).map(|i| 14e-9 - i as f64 * 0.4e-9).collect();
    let values = gaps(&probe, &z_c);
    let spec = FmSpec {
        mode: 2,
        ..FmSpec::new(probe.params, values, 1.0)
    };
    let curve = fm_curve(&spec, &Progress::new()).unwrap();
    assert!(curve.unreached.is_none(), "{:?}", curve.unreached);
    let s = &probe.scales;
    let k2 = curve.reference.stiffness * s.force_n / s.length_m;
    let f2 = s.frequency_hz(curve.reference.omega);
    assert!((k2 / 40.0 - 39.3).abs() < 0.5, "k2 = {k2}");
    assert!((f2 / 300e3 - 6.27).abs() < 0.05, "f2 = {f2}");
    for (p, &zc) in curve.points.iter().zip(&z_c) {
        let df = s.frequency_hz(p.omega - curve.reference.omega);
        let centre = zc + p.observables.mean_deflection * g0;
        let d_min = p.observables.min_distance * g0;
        let expected = giessibl(centre, g0, k2, f2);
        let bound = vdw(d_min).abs() / (k2 * g0);
        let rel = (df - expected).abs() / expected.abs();
        assert!(
            rel <= 3.0 * bound + 1e-5,
            "z_c {zc}: {df} vs {expected} ({rel:e})"
        );
    }
}

/// `fm` with a temperature (the Q = 400 lever of `PROBE` at A = 10 nm, 295 K): far from the
/// sample, where the lever is free, σ of the frequency shift at the loops' bandwidth is
/// Albrecht's thermal frequency noise √(f₀ k_BT B/(π k Q A²)) (Albrecht, Grütter, Horne & Rugar,
/// *J. Appl. Phys.* 69 (1991) 668, eq. 11) within 1 % for a loop slow against the lever
/// (B = 20 Hz against f₀/2Q = 375 Hz; measured 10⁻⁵); at 0.6 nm from the sample (Δf = −19 Hz)
/// the force gradient turns the amplitude's noise into the frequency's: σ is 1.33 times it.
/// The document's `thermal` block states T, B and the gain; σ scales as √T (1 180 K warns, a
/// value in °C?) and, for the slow loop, as √B; a bandwidth without a temperature, or
/// faster than the lever, is refused naming `bandwidth`; the table and the layout carry the
/// columns.
#[test]
fn a_temperature_gives_the_frequency_shift_noise() {
    use afmdyn::request::{named, Resolved};
    let text = PROBE.replace("quality_factor = 1e4", "quality_factor = 400");
    let probe = Probe::parse(&text, "q400").unwrap();
    let model = Resolved {
        params: probe.params,
        probe: Some(probe),
    };
    let request = |t: f64, b: f64| {
        let r = serde_json::json!({"temperature": t, "bandwidth": b, "from": 20e-9,
            "to": 10.6e-9, "points": 4});
        named::parse("fm", r).unwrap().unwrap()
    };
    let run = |t: f64, b: f64| request(t, b).run(&model, &Default::default()).unwrap();
    let out = run(295.0, 20.0);
    let doc = &out.document;
    assert_eq!(doc["warnings"], serde_json::json!([]));
    let sigma =
        |d: &serde_json::Value, i: usize| d["curve"]["frequency_shift_noise"][i].as_f64().unwrap();
    let (f0, k, q, a) = (300e3, 40.0, 400.0, 10e-9);
    let kt = 1.380_649e-23 * 295.0;
    let albrecht = (f0 * kt * 20.0 / (PI * k * q * a * a)).sqrt();
    println!("σ_Δf = {:.5e} Hz (Albrecht {albrecht:.5e})", sigma(doc, 0));
    assert!(
        (sigma(doc, 0) / albrecht - 1.0).abs() < 0.01,
        "{}",
        doc["thermal"]
    );
    assert!(sigma(doc, 3) > 1.2 * sigma(doc, 0), "{}", doc["curve"]);
    assert_eq!(doc["thermal"]["temperature"], 295.0);
    assert!((doc["thermal"]["bandwidth"].as_f64().unwrap() / 20.0 - 1.0).abs() < 1e-12);
    assert_eq!(doc["units"]["frequency_shift_noise"], "Hz");
    let hot = run(4.0 * 295.0, 20.0).document;
    assert!((sigma(&hot, 2) / sigma(doc, 2) - 2.0).abs() < 1e-9);
    assert!(
        hot["warnings"][0].as_str().unwrap().contains("°C"),
        "{}",
        hot["warnings"]
    );
    let wide = run(295.0, 80.0).document;
    assert!((sigma(&wide, 0) / sigma(doc, 0) - 2.0).abs() < 0.02);
    let layout = &out.datasets[0].1;
    assert!(layout
        .variables
        .iter()
        .any(|v| v.name == "excitation_noise"));
    let refused = |r: serde_json::Value| {
        let r = named::parse("fm", r).unwrap().unwrap();
        r.run(&model, &Default::default()).unwrap_err().to_string()
    };
    let alone = refused(serde_json::json!({"bandwidth": 20.0, "points": 2}));
    assert!(
        alone.contains("bandwidth") && alone.contains("temperature"),
        "{alone}"
    );
    let fast = refused(serde_json::json!({"temperature": 295.0, "bandwidth": 1e4, "points": 2}));
    assert!(
        fast.contains("bandwidth") && fast.contains("outruns"),
        "{fast}"
    );
    // below Q = π/2 the gain's bound is 1 per cycle (π/Q would pass 2, where a first-order loop
    // diverges, and once gave a negative largest bandwidth that refused every one)
    let text = PROBE.replace("quality_factor = 1e4", "quality_factor = 1.2");
    let probe = Probe::parse(&text, "q1.2").unwrap();
    let low = Resolved {
        params: probe.params,
        probe: Some(probe),
    };
    let r = serde_json::json!({"temperature": 295.0, "bandwidth": 100.0, "points": 2});
    let r = named::parse("fm", r).unwrap().unwrap();
    let doc = r.run(&low, &Default::default()).unwrap().document;
    assert!((doc["thermal"]["bandwidth"].as_f64().unwrap() / 100.0 - 1.0).abs() < 1e-12);
}

//! Multifrequency (bimodal) AFM: the drive as a sum of components at commensurate
//! frequencies (`[drive] free_amplitude = [A01, A02]`, `frequency = [f1, f2]`), the steady
//! state a periodic orbit of the common period, each component's amplitude, phase, virial and
//! dissipated energy by demodulation (Lozano & García, Phys. Rev. Lett. 100, 076102 (2008);
//! García & Proksch, Eur. Polym. J. 49, 1897 (2013)).

use afmdyn::analysis::observables::observe_orbit;
use afmdyn::analysis::shooting::{shoot, ShootingOptions};
use afmdyn::integrate::{build, IntegratorKind, IntegratorOptions};
use afmdyn::maps::StroboscopicMap;
use afmdyn::probe::Probe;
use afmdyn::CantileverModel;

/// The eigenmode model of the checks: mode 2 at 1.88 MHz, Q = [400, 2507], driven there.
fn eigenmodes() -> String {
    common::bimodal_lever("1.88e6", "400, 2507", "1.88e6")
}

use super::common;
use common::opts;

/// The integrator of the checks: auto (Taylor for DMT) at 1e-12.
fn integ() -> IntegratorOptions {
    opts(IntegratorKind::Auto, 1e-12)
}

/// Far from the sample each component's amplitude is its free amplitude and its phase the
/// free response's (≤ 1e-6), the primary's 90° at resonance.
#[test]
fn far_from_the_sample_each_component_is_free() {
    let probe = Probe::parse(&eigenmodes(), "test").unwrap();
    assert_eq!(probe.components.len(), 1);
    assert_eq!(probe.components[0].ratio, [94, 15]);
    let mut p = probe.params;
    p.alpha5 = p.alpha5_for_rest_distance(1e-6 / probe.scales.length_m);
    assert_eq!(p.common_periods(), 15);
    let model = CantileverModel::new(&p).unwrap();
    let mut it = build(&model, IntegratorOptions::default(), 0.0, &model.rest()).unwrap();
    let map = &mut StroboscopicMap::new(it.as_mut(), 1);
    let orbit = shoot(
        map,
        &nalgebra::DVector::zeros(4),
        &ShootingOptions::default(),
    )
    .unwrap();
    let o = observe_orbit(&model, integ(), &orbit, 3).unwrap();
    assert_eq!(o.components.len(), 2);
    for c in &o.components {
        eprintln!("{c:?}");
        assert!((c.amplitude / c.free_amplitude - 1.0).abs() < 1e-6);
        assert!((c.phase - c.free_phase).abs() < 1e-6);
    }
    assert!((o.components[0].free_amplitude - 1.0).abs() < 1e-12);
    assert!((o.components[1].free_amplitude - 0.1).abs() < 1e-12);
}

/// The point mass driven at its resonance and at 25/4 of it, over a conservative DMT sample:
/// projecting z'' + z'/Q + z = F₁ cos τ + F₂ cos(25τ/4) + F_c on ż_c and z_c makes the
/// closed forms of the primary component exact (module docs of the observables:
/// E₁ = (πA₁²/Q)[(A₀₁/A₁) sin φ₁ − 1], V₁ = −A₁A₀₁ cos φ₁/(2Q)); each mode's energy balance
/// (drive − damping − sample, the further component's work included) closes; the total
/// dissipation of a conservative law is zero.
#[test]
fn point_mass_component_balances_are_exact() {
    let probe = Probe::parse(
        r#"
model = "point-mass"
[cantilever]
spring_constant = 40.0
resonance_frequency = 300e3
quality_factor = 400
[tip]
radius = 10e-9
[sample]
law = "dmt"
youngs_modulus = 4e9
poisson_ratio = 0.33
hamaker = 6.6e-20
[drive]
free_amplitude = [10e-9, 0.5e-9]
frequency = [300e3, 1.875e6]
"#,
        "test",
    )
    .unwrap();
    assert_eq!(probe.components[0].ratio, [25, 4]);
    let g0 = probe.scales.length_m;
    let mut checked = 0;
    for z_c in [9.0e-9, 6.0e-9, 3.0e-9] {
        let mut p = probe.params;
        p.alpha5 = p.alpha5_for_rest_distance(z_c / g0);
        let model = CantileverModel::new(&p).unwrap();
        // settle from rest, then the periodic orbit of the common period
        let mut it = afmdyn::integrate::build(&model, integ(), 0.0, &model.rest()).unwrap();
        let settled = afmdyn::analysis::steady::steady_state(
            it.as_mut(),
            &afmdyn::analysis::steady::SteadyOptions::default(),
        )
        .unwrap();
        let start = settled.end_state().clone();
        let mut fresh = build(&model, IntegratorOptions::default(), 0.0, &model.rest()).unwrap();
        let map = &mut StroboscopicMap::new(fresh.as_mut(), 1);
        let Ok(orbit) = shoot(map, &start, &ShootingOptions::default()) else {
            continue;
        };
        let o = observe_orbit(&model, integ(), &orbit, 3).unwrap();
        let c1 = &o.components[0];
        let scale = PI_OVER_Q * c1.free_amplitude * c1.free_amplitude;
        assert!(
            (c1.energy_dissipated - c1.closed_energy_dissipated).abs() < 1e-7 * scale,
            "E1 {} vs {}",
            c1.energy_dissipated,
            c1.closed_energy_dissipated
        );
        assert!(
            (c1.virial - c1.closed_virial).abs() < 1e-7 * scale,
            "V1 {} vs {}",
            c1.virial,
            c1.closed_virial
        );
        for b in &o.mode_balance {
            assert!(b.residual.abs() < 1e-8 * scale, "mode balance {b:?}");
        }
        assert!(o.energy_dissipated.abs() < 1e-8 * scale);
        checked += 1;
    }
    assert_eq!(checked, 3);
}

const PI_OVER_Q: f64 = std::f64::consts::PI / 400.0;

/// The eigenmode model's approach curve (two modes, each driven at its resonance): the
/// closed forms of each component (Lozano & García 2008) agree with the direct integrals to
/// within the terms they neglect (the other mode's response at the component's frequency,
/// here ≤ 1e-3 of π k A₀²/Q), and the single-harmonic integrators (exact, split) are refused
/// naming the integrator.
#[test]
fn eigenmode_approach_components_match_their_closed_forms() {
    use afmdyn::analysis::approach::{approach_retract, approach_spec};
    use afmdyn::analysis::stepped::Spacing;
    let text = eigenmodes().replace("1.88e6", "1.875e6");
    let probe = Probe::parse(&text, "test").unwrap();
    assert_eq!(probe.components[0].ratio, [25, 4]);
    let g0 = probe.scales.length_m;
    let mut spec = approach_spec(probe.params, 10e-9 / g0, 3e-9 / g0, Spacing::Points(15)).unwrap();
    spec.branches = false;
    let c = approach_retract(&spec).unwrap();
    let mut reduced = false;
    for p in &c.first {
        let o = &p.observables;
        assert_eq!(o.components.len(), 2);
        for (i, k) in o.components.iter().enumerate() {
            assert_eq!(k.mode, i);
            let (stiff, q) = if i == 0 {
                (1.0, 400.0)
            } else {
                (1571.0 / 40.0, 2500.0)
            };
            let scale = std::f64::consts::PI * stiff * k.free_amplitude.powi(2) / q;
            assert!(
                (k.energy_dissipated - k.closed_energy_dissipated).abs() < 1e-3 * scale,
                "component {i} at {}: E {} vs {}",
                p.value,
                k.energy_dissipated,
                k.closed_energy_dissipated
            );
            assert!(
                (k.virial - k.closed_virial).abs() < 1e-3 * scale,
                "component {i} at {}: V {} vs {}",
                p.value,
                k.virial,
                k.closed_virial
            );
        }
        reduced |= o.components[0].amplitude < 0.9 * o.components[0].free_amplitude;
    }
    assert!(reduced, "the curve reaches the sample");
    let model = CantileverModel::new(&probe.params).unwrap();
    for kind in [IntegratorKind::Exact, IntegratorKind::Split] {
        let opts = IntegratorOptions {
            kind,
            ..IntegratorOptions::default()
        };
        let e = afmdyn::integrate::build(&model, opts, 0.0, &model.rest())
            .err()
            .expect("refused");
        assert!(e.to_string().contains("integrator"), "{e}");
    }
}

const BEAM_HEAD: &str = "model = \"beam\"\nmodes = 3\n[cantilever]\nspring_constant = 40.0\n\
                         resonance_frequency = 300e3\nquality_factor = 400\n";
const BEAM_TAIL: &str = r#"
[tip]
radius = 10e-9
[sample]
law = "dmt"
youngs_modulus = 4e9
poisson_ratio = 0.33
hamaker = 6.6e-20
[drive]
free_amplitude = [10e-9, 1e-9]
frequency = [300e3, 1.875e6]
"#;

/// The two-mode eigenmode model with the Galerkin beam's k̃_j, f_j, Q_j (N = 3, base drive
/// for component 1, a tip force for component 2 at 6.25 f₁) follows the beam in the attractive
/// regime under the same bimodal drive: each component's amplitude within 0.5 % of its free
/// amplitude and its phase within 1° (0.05° far from the sample, 0.76° where the attraction
/// sets in at z_c = 11 nm; the beam's third mode, its base motion in V_T and the
/// coupling of its modes are what the two-mode model leaves out).
#[test]
fn two_eigenmodes_follow_the_beam_under_a_bimodal_drive() {
    use afmdyn::analysis::approach::{approach_retract, approach_spec};
    use afmdyn::analysis::stepped::Spacing;
    let beam = Probe::parse(&format!("{BEAM_HEAD}{BEAM_TAIL}"), "test").unwrap();
    let eig = common::two_modes_of(&beam, BEAM_TAIL);
    let g0 = beam.scales.length_m;
    assert_eq!(beam.scales.length_m, eig.scales.length_m);
    let run = |p: &Probe| {
        let mut spec = approach_spec(p.params, 14e-9 / g0, 11e-9 / g0, Spacing::Points(8)).unwrap();
        spec.branches = false;
        approach_retract(&spec).unwrap().first
    };
    let (b, e) = (run(&beam), run(&eig));
    let mut attractive = 0;
    for (x, y) in b.iter().zip(&e) {
        let (ox, oy) = (&x.observables, &y.observables);
        for i in 0..2 {
            let (cx, cy) = (&ox.components[i], &oy.components[i]);
            assert!(
                (cx.amplitude / cx.free_amplitude - cy.amplitude / cy.free_amplitude).abs() < 5e-3,
                "component {i} at {}: A beam {} eigenmodes {}",
                x.value,
                cx.amplitude,
                cy.amplitude
            );
            assert!(
                (cx.phase - cy.phase).abs().to_degrees() < 1.0,
                "component {i} at {}: φ beam {} eigenmodes {}",
                x.value,
                cx.phase.to_degrees(),
                cy.phase.to_degrees()
            );
        }
        attractive += usize::from(ox.components[0].phase > std::f64::consts::FRAC_PI_2 + 0.01);
    }
    assert!(attractive >= 3, "the attractive regime is reached");
}

/// The energy balance of a multifrequency drive closes: over one common period of the
/// eigenmode model (each mode with its own Q, the second driven at its resonance), the change
/// of E = ½ȧᵀMȧ + ½aᵀKa equals the drive's work (the further component's F̃(τ)Ẇ included)
/// minus the damping's ȦᵀC^IȦ (the per-mode C^I_jj = k_j/(ω_jQ_j), which the power once took
/// as α3 for every mode) — both integrated by a 200 000-interval Simpson rule on the
/// integrator's dense output, to 1e-9 of the work.
#[test]
fn the_energy_balance_closes_with_each_modes_damping() {
    let text = eigenmodes().replace("1.88e6", "1.875e6");
    let probe = Probe::parse(&text, "test").unwrap();
    let mut p = probe.params;
    p.alpha5 = 10.0;
    let m = CantileverModel::new(&p).unwrap();
    let z0 = nalgebra::DVector::zeros(4);
    let mut it =
        afmdyn::integrate::build(&m, opts(IntegratorKind::Adaptive, 1e-13), 0.0, &z0).unwrap();
    let t_end = m.period();
    let n = 200_000;
    let h = t_end / n as f64;
    let (mut work, mut damping) = (0.0, 0.0);
    let mut z_end = z0.clone();
    for i in 0..=n {
        let t = i as f64 * h;
        while it.tau() < t {
            it.step(t_end).unwrap();
        }
        let z = it.dense_state(t);
        let w = if i == 0 || i == n {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        let pw = m.power(afmdyn::Region::Free, t, &z);
        work += w * pw.base * h / 3.0;
        damping += w * pw.beam_dissipation * h / 3.0;
        z_end = z;
    }
    let de =
        m.energy(afmdyn::Region::Free, t_end, &z_end) - m.energy(afmdyn::Region::Free, 0.0, &z0);
    assert!(
        (de - (work - damping)).abs() < 1e-9 * work,
        "ΔE {de} vs W − D {}",
        work - damping
    );
}

/// The Taylor integrator's series carry every drive component (in τ in free flight and in the
/// contact's interior, in the regularising σ at its edges): on the eigenmode model's periodic
/// orbits — free, attractive and in repulsive DMT contact with a viscous sample — its orbit
/// and each component's amplitude and phase equal those of the adaptive DOP853 at 1e-13
/// (an independent integrator) to 1e-8, and its per-step energy integrals close the balance.
#[test]
fn taylor_agrees_with_dop853_under_a_bimodal_drive() {
    let text = eigenmodes()
        .replace("1.88e6", "1.875e6")
        .replace("z_c = 8e-9", "z_c = 8e-9\nviscosity = 50.0");
    let probe = Probe::parse(&text, "test").unwrap();
    let g0 = probe.scales.length_m;
    let mut contact = 0;
    for z_c in [20e-9, 10.5e-9, 6e-9, 3e-9] {
        let mut p = probe.params;
        p.alpha5 = p.alpha5_for_rest_distance(z_c / g0);
        let model = CantileverModel::new(&p).unwrap();
        let mut it = afmdyn::integrate::build(
            &model,
            opts(IntegratorKind::Adaptive, 1e-12),
            0.0,
            &model.rest(),
        )
        .unwrap();
        let settled = afmdyn::analysis::steady::steady_state(
            it.as_mut(),
            &afmdyn::analysis::steady::SteadyOptions::default(),
        )
        .unwrap();
        let shoot_with = |kind, tol| {
            let mut it =
                afmdyn::integrate::build(&model, opts(kind, tol), 0.0, &model.rest()).unwrap();
            let orbit = shoot(
                &mut StroboscopicMap::new(it.as_mut(), 1),
                settled.end_state(),
                &ShootingOptions {
                    tol: 1e-12,
                    max_iter: 20,
                    ..ShootingOptions::default()
                },
            )
            .unwrap();
            let o = observe_orbit(&model, opts(kind, tol), &orbit, 3).unwrap();
            (orbit, o)
        };
        assert_eq!(
            IntegratorKind::Auto.resolve(&model),
            IntegratorKind::Taylor,
            "auto takes the Taylor integrator"
        );
        let (ta, ot) = shoot_with(IntegratorKind::Taylor, 1e-13);
        let (da, od) = shoot_with(IntegratorKind::Adaptive, 1e-13);
        let diff = (&ta.state - &da.state).amax();
        assert!(
            diff < 1e-8 * (1.0 + da.state.amax()),
            "z_c {z_c}: orbit differs by {diff}"
        );
        for (a, b) in ot.components.iter().zip(&od.components) {
            assert!(
                (a.amplitude - b.amplitude).abs() < 1e-8 * b.free_amplitude,
                "{a:?} {b:?}"
            );
            assert!((a.phase - b.phase).abs() < 1e-8, "{a:?} {b:?}");
            let scale = b.free_amplitude * b.free_amplitude;
            assert!((a.energy_dissipated - b.energy_dissipated).abs() < 1e-8 * scale);
        }
        for bal in &ot.mode_balance {
            assert!(bal.residual.abs() < 1e-9, "{bal:?}");
        }
        contact += usize::from(ot.contact_fraction > 0.0);
    }
    assert!(contact >= 2, "the orbits reach the contact");
}

/// A ratio that needs a long common period (201/64: 64 drive periods per orbit) gives a curve
/// with a warning naming it; the beam's own f₂/f₁ (each component at its mode's resonance,
/// the default) is taken within 1e-6 as 1855/296.
#[test]
fn a_long_common_period_is_warned_of() {
    use afmdyn::analysis::approach::{approach_retract, approach_spec};
    use afmdyn::analysis::stepped::Spacing;
    let text = eigenmodes()
        .replace("model = \"eigenmodes\"", "model = \"point-mass\"")
        .replace("[40.0, 1571.0]", "40.0")
        .replace(
            "[300e3, 1.88e6]\nquality_factor = [400, 2507]",
            "300e3\nquality_factor = 400",
        )
        .replace(
            "frequency = [300e3, 1.88e6]",
            "frequency = [300e3, 942187.5]",
        );
    let probe = Probe::parse(&text, "test").unwrap();
    assert_eq!(probe.components[0].ratio, [201, 64]);
    let g0 = probe.scales.length_m;
    let mut spec = approach_spec(probe.params, 12e-9 / g0, 11e-9 / g0, Spacing::Points(2)).unwrap();
    spec.branches = false;
    let c = approach_retract(&spec).unwrap();
    assert!(
        c.warnings
            .iter()
            .any(|w| w.contains("every 64 drive periods") && w.contains("201/64")),
        "{:?}",
        c.warnings
    );
    let beam = Probe::parse(
        &format!(
            "{BEAM_HEAD}{}",
            BEAM_TAIL.replace("frequency = [300e3, 1.875e6]\n", "")
        ),
        "test",
    )
    .unwrap();
    assert_eq!(beam.components[0].ratio, [1855, 296]);
    let f2 = beam.components[0].frequency;
    let (free, _) = afmdyn::eigen::spectrum(&beam.params).unwrap();
    let natural = beam.scales.frequency_hz(free.omega[1]);
    assert!((f2 / natural - 1.0).abs() <= 1e-6, "{f2} vs {natural}");
}

/// `bimodal` with a temperature (examples/probe-bimodal.toml: modes of 40 and 1571 N/m at
/// 300 kHz and 1.875 MHz = 25/4 f₁, Q = 400 and 2500): every exact orbit of both sweeps gains
/// each component's lock-in noise, `amplitude_noise`/`phase_noise_deg` (the first's) and
/// `amplitude_noise_2`/`phase_noise_2_deg`, listed in the `"thermal"` and `"drive_components"`
/// blocks. Far from the sample each mode is free and at its resonance with Q ≫ 1, so each
/// lock-in reads its own mode's σ_A² = (k_BT/k_j) τ_j/(τ_j + τ_L), τ_j = 2Q_j/ω_j (the slow
/// amplitude's response behind the lock-in's filter; equipartition at τ_L → 0): within 1 %,
/// and σ_φ = σ_A/A_j. Measured on time averages instead, the points have no noise, and say so.
#[test]
fn a_temperature_gives_each_components_lock_in_noise() {
    use afmdyn::analysis::progress::Progress;
    use afmdyn::request::{run, ApproachRequest, Bimodal, CurveRequest, Resolved};
    let text = include_str!("../../../examples/probe-bimodal.toml");
    let probe = Probe::parse(text, "bimodal").expect("example probe");
    let model = Resolved {
        params: probe.params,
        probe: Some(probe.clone()),
    };
    let hot = |average: bool| {
        Bimodal(ApproachRequest {
            curve: CurveRequest {
                points: Some(6),
                branches: false,
                ..CurveRequest::default()
            },
            temperature: Some(295.0),
            average,
            ..ApproachRequest::default()
        })
    };
    let doc = run(&hot(false), &model, &Progress::new()).unwrap().json;
    let columns = [
        "amplitude_noise",
        "phase_noise_deg",
        "amplitude_noise_2",
        "phase_noise_2_deg",
    ];
    assert_eq!(doc["thermal"]["columns"], serde_json::json!(columns));
    let listed = doc["drive_components"]["columns"].to_string();
    assert!(listed.contains("amplitude_noise_2") && listed.contains("phase_noise_2_deg"));
    let tl = doc["thermal"]["time_constant"].as_f64().unwrap();
    let kt = 1.380_649e-23 * 295.0;
    let sweep = &doc["approach"];
    let at = |key: &str| sweep[key][0].as_f64().unwrap();
    for (j, (k, q, f)) in [(40.0, 400.0, 300e3), (1571.0, 2500.0, 1.875e6)]
        .into_iter()
        .enumerate()
    {
        let tau = 2.0 * q / (std::f64::consts::TAU * f);
        let free = (kt / k * tau / (tau + tl)).sqrt();
        let name = |what: &str| match j {
            0 => format!("{what}_noise{}", if what == "phase" { "_deg" } else { "" }),
            _ => format!(
                "{what}_noise_2{}",
                if what == "phase" { "_deg" } else { "" }
            ),
        };
        let sigma = at(&name("amplitude"));
        eprintln!("mode {}: σ_A = {sigma:e} m (closed form {free:e})", j + 1);
        assert!((sigma / free - 1.0).abs() < 0.01, "{sigma} vs {free}");
        let a = at(&format!("amplitude_{}", j + 1));
        let phase = at(&name("phase")).to_radians();
        assert!((phase * a / free - 1.0).abs() < 0.01, "{phase} {a} {free}");
        for sweep in ["approach", "retract"] {
            assert_eq!(doc[sweep][name("amplitude")].as_array().unwrap().len(), 6);
        }
    }
    // time averages have no orbit to take the noise about: null, and said
    let doc = run(&hot(true), &model, &Progress::new()).unwrap().json;
    assert!(doc["approach"]["amplitude_noise_2"]
        .as_array()
        .unwrap()
        .iter()
        .all(|v| v.is_null()));
    let said = doc["warnings"].to_string();
    assert!(said.contains("12 point(s) are time averages"), "{said}");
}

//! Observables of a steady state (`analysis::observables`): the free response against the
//! closed-form harmonic response, the exact period balances of the point-mass model in contact
//! (and how far the plain closed forms of Cleveland/Anczykowski and San Paulo & García are off),
//! the per-mode energy balance of the beam, and independent checks of THD, mean deflection,
//! contact fraction and peak force.

use super::common;

use afmdyn::analysis::observables::{observe_from, observe_orbit, ObservableOptions, Observables};
use afmdyn::analysis::shooting::{shoot, ShootingOptions};
use afmdyn::analysis::steady::{steady_state, Motion, SteadyOptions};
use afmdyn::integrate::{advance_dyn, build, IntegratorOptions};
use afmdyn::maps::StroboscopicMap;
use afmdyn::report;
use afmdyn::trajectory::{record, RecordSpec};
use afmdyn::{CantileverModel, ContactLaw, Params, Region, SimError, Structure};
use common::{events_until, harmonic_response};
use nalgebra::DVector;
use std::f64::consts::{FRAC_PI_2, PI};

/// The point-mass model z'' + α3 z' + z = α2 cos Ωτ + F_c (Q = 1/α3, A₀ = Q α2 at Ω = 1).
fn point_mass(law: ContactLaw, omega: f64, alpha5: f64) -> Params {
    Params {
        structure: Structure::PointMass,
        modes: 1,
        alpha1: 0.0,
        alpha2: 0.1,
        alpha3: 0.1,
        alpha4: 10.0,
        alpha5,
        alpha6: 0.05,
        omega,
        contact_law: law,
        ..Params::default()
    }
}

/// The integrator of the tests: the exact propagator for the linear law, the adaptive one at
/// tolerance 1e-14 otherwise (its dense output then accurate well below the 1e-8 of the
/// balances).
fn integ() -> IntegratorOptions {
    IntegratorOptions {
        kind: afmdyn::IntegratorKind::Auto,
        steps_per_period: 1,
        tolerance: 1e-14,
        ..Default::default()
    }
}

/// A period-n orbit of `model` at τ = 0: a transient from rest, then Newton shooting; checked
/// periodic by one more run of n periods.
fn orbit(model: &CantileverModel, n: usize) -> DVector<f64> {
    let mut it = build(model, integ(), 0.0, &model.rest()).unwrap();
    advance_dyn(it.as_mut(), 60.0 * model.period(), &mut |_, _, _| Ok(())).unwrap();
    let guess = it.state().clone();
    let opts = ShootingOptions {
        tol: 1e-12,
        period: n,
        ..ShootingOptions::default()
    };
    let o = shoot(&mut StroboscopicMap::new(it.as_mut(), 1), &guess, &opts).unwrap();
    it.reset(0.0, &o.state).unwrap();
    advance_dyn(
        it.as_mut(),
        n as f64 * model.period(),
        &mut |_, _, _| Ok(()),
    )
    .unwrap();
    let gap = (it.state() - &o.state).norm();
    assert!(
        gap <= 1e-10 * (1.0 + o.state.norm()),
        "not periodic: {gap:e}"
    );
    o.state
}

/// Observables from (0, z) with [`integ`].
fn observe(
    model: &CantileverModel,
    z: &DVector<f64>,
    periods: usize,
    harmonics: usize,
) -> Observables {
    observe_from(
        model,
        integ(),
        0.0,
        z,
        &ObservableOptions { periods, harmonics },
    )
    .unwrap()
}

/// The first harmonic of `o` is (a, φ) to 1e-9 (relative, resp. absolute in rad), and so is the
/// free amplitude of its closed forms (1e-12).
fn assert_free_response(o: &Observables, a: f64, phi: f64, omega: f64) {
    println!(
        "free response Ω = {omega}: ΔA/A = {:.1e}, Δφ = {:.1e} rad",
        rel(o.amplitude, a, a),
        o.phase - phi
    );
    assert!(
        rel(o.amplitude, a, a) <= 1e-9,
        "Ω = {omega}: {} vs {a}",
        o.amplitude
    );
    assert!(
        (o.phase - phi).abs() <= 1e-9,
        "Ω = {omega}: {} vs {phi}",
        o.phase
    );
    assert!(rel(o.closed_form.free_amplitude, a, a) <= 1e-12);
}

fn rel(a: f64, b: f64, scale: f64) -> f64 {
    (a - b).abs() / scale
}

/// Free oscillation far from the sample (α5 = 1e3): amplitude and lag of the first harmonic
/// equal the closed-form linear harmonic response. Point mass: A = α2/√((1 − Ω²)² + (α3Ω)²),
/// tan φ = α3Ω/(1 − Ω²) (e.g. Meirovitch, *Fundamentals of Vibrations*, 2001, §3.2), φ = 90° at
/// Ω = 1. Beam N = 3: the complex modal response of `common::harmonic_response` (eq. 10 solved
/// in the second-order form), sampled at τ = 0 and T/4. Started on the periodic response itself.
#[test]
fn free_oscillation_matches_the_harmonic_response() {
    for omega in [1.0, 0.93, 1.2] {
        let p = point_mass(ContactLaw::Linear, omega, 1e3);
        let model = CantileverModel::new(&p).unwrap();
        let z0 = harmonic_response(&model, Region::Free, 0.0);
        let o = observe(&model, &z0, 2, 5);
        let a = p.alpha2 / ((1.0 - omega * omega).powi(2) + (p.alpha3 * omega).powi(2)).sqrt();
        let phi = (p.alpha3 * omega).atan2(1.0 - omega * omega);
        assert_free_response(&o, a, phi, omega);
        assert!((o.closed_form.free_phase - phi).abs() <= 1e-12);
        // a window that starts inside a period gives the same harmonics
        let tau0 = 0.37 * model.period();
        let z1 = harmonic_response(&model, Region::Free, tau0);
        let o1 = observe_from(&model, integ(), tau0, &z1, &ObservableOptions::default()).unwrap();
        assert_free_response(&o1, a, phi, omega);
        assert!(o.thd <= 1e-6, "harmonic response: THD {}", o.thd);
        assert!(o.mean_deflection.abs() <= 1e-9 * a);
        assert_eq!(
            (o.contact_fraction, o.energy_dissipated, o.virial),
            (0.0, 0.0, 0.0)
        );
        if omega == 1.0 {
            assert!(
                (o.phase - FRAC_PI_2).abs() <= 1e-9,
                "phase at resonance {}",
                o.phase
            );
        }
    }
    for omega in [0.5, 2.8, 3.4] {
        let p = Params {
            omega,
            alpha5: 1e3,
            ..Params::default()
        };
        let model = CantileverModel::new(&p).unwrap();
        let z0 = harmonic_response(&model, Region::Free, 0.0);
        let o = observe(&model, &z0, 1, 3);
        // W(τ) = Re ŵ cos Ωτ − Im ŵ sin Ωτ = A sin(Ωτ − φ)
        let w0 = model.w_tip(&z0);
        let w1 = model.w_tip(&harmonic_response(
            &model,
            Region::Free,
            0.25 * model.period(),
        ));
        let a = w0.hypot(w1);
        let phi = (-w0).atan2(w1);
        assert_free_response(&o, a, phi, omega);
        println!(
            "beam N = 3, Ω = {omega}: A₀ = {a:.6e}, φ₀ = {:.4}°, k̃ = {:.4}, Q₁ = {:.3}, ω₁ = {:.5}",
            phi.to_degrees(),
            o.closed_form.stiffness,
            o.closed_form.quality_factor,
            o.closed_form.natural_frequency
        );
    }
}

/// Point mass in steady state with contact: the direct E_dis = −∮F_c ż and V = ⟨F_c z⟩ satisfy
/// the exact period balances of the module docs (equation of motion times ż resp. z, averaged,
/// with Parseval):
/// E_dis = π F₀ A sin φ − (π/Q) Ω Σₙ n²Aₙ²,
/// V = ⟨z⟩² + ½ Σₙ (1 − n²Ω²) Aₙ² − ½ F₀ A cos φ,
/// and at Ω = 1 the forms E_cf − E_dis = (π k/Q) Σ_{n≥2} n²Aₙ², V − V_cf = k⟨z⟩² +
/// (k/2) Σ_{n≥2} (1 − n²)Aₙ² with E_cf of Cleveland et al. (1998)/Anczykowski et al. (1999)
/// and V_cf of San Paulo & García (2001) (off resonance with the extra terms of F₀ ≠ kA₀/Q).
/// Each to ≤ 1e-8 of the largest term. Prints how far
/// the plain closed forms are off. Phase regime: repulsive (linear, Hertz at a small gap)
/// φ < 90° and V < 0; attractive (DMT, van der Waals only) φ > 90° and V > 0.
#[test]
fn point_mass_period_balances_are_exact() {
    let dmt = ContactLaw::Dmt {
        hamaker: 2e-4,
        intermolecular_distance: 0.02,
    };
    let cases = [
        ("linear", ContactLaw::Linear, 1.0, 0.6, Some(true)),
        ("linear", ContactLaw::Linear, 0.97, 0.6, Some(true)),
        ("hertz", ContactLaw::Hertz, 1.0, 0.5, Some(true)),
        ("dmt", dmt, 1.0, 0.5, None),
        ("dmt (attractive)", dmt, 1.0, 0.995, Some(false)),
    ];
    for (name, law, omega, alpha5, repulsive) in cases {
        let p = point_mass(law, omega, alpha5);
        let model = CantileverModel::new(&p).unwrap();
        let z0 = orbit(&model, 1);
        let o = observe(&model, &z0, 1, 10);
        let (a, phi, f0, q) = (o.amplitude, o.phase, p.alpha2, 1.0 / p.alpha3);
        let (s1, s2, mean) = (o.higher_sq, o.higher_n2_sq, o.mean_deflection);
        // energy: E_dis = π F₀ A sin φ − (π/Q) Ω (A² + Σ_{n≥2} n²Aₙ²)
        let (input, damping) = (PI * f0 * a * phi.sin(), PI / q * omega * (a * a + s2));
        let scale = input.abs().max(damping.abs());
        let e_err = rel(o.energy_dissipated, input - damping, scale);
        // virial: V = ⟨z⟩² + ½(1 − Ω²)A² + ½(Σ Aₙ² − Ω² Σ n²Aₙ²)_{n≥2} − ½ F₀ A cos φ
        let terms = [
            mean * mean,
            0.5 * (1.0 - omega * omega) * a * a,
            0.5 * (s1 - omega * omega * s2),
            -0.5 * f0 * a * phi.cos(),
        ];
        let v_scale = terms.iter().fold(0.0f64, |m, t| m.max(t.abs()));
        let v_err = rel(o.virial, terms.iter().sum(), v_scale);
        assert!(
            o.energy_dissipated > 0.0 || name.contains("attractive"),
            "{name}"
        );
        assert!(
            e_err <= 1e-8,
            "{name} Ω = {omega}: energy balance off by {e_err:e}"
        );
        assert!(
            v_err <= 1e-8,
            "{name} Ω = {omega}: virial balance off by {v_err:e}"
        );
        let cf = o.closed_form;
        // the closed forms' point mass: k = 1, Q = 1/α3, ω₀ = 1, F₀ = α2 (the model equation)
        let (k, a0) = (cf.stiffness, cf.free_amplitude);
        assert!(rel(k, 1.0, 1.0) <= 1e-12 && rel(cf.quality_factor, q, q) <= 1e-12);
        assert!(rel(cf.natural_frequency, 1.0, 1.0) <= 1e-12);
        assert!(rel(cf.drive_force, f0, f0) <= 1e-12);
        // E_cf − E_dis = (πk/Q)(ω/ω₀) Σ_{n≥2} n²Aₙ² + π A sin φ (kA₀/Q − F₀), the last term 0 at
        // ω = ω₀; V − V_cf = k⟨z⟩² + (k/2) Σ_{n≥2}(1 − n²ω²)Aₙ² + (k/2)(1 − ω²)A²
        // − ½ A cos φ (F₀ − kA₀/Q) (module docs of analysis::observables)
        let off = f0 - k * a0 / q;
        if omega == 1.0 {
            assert!(off.abs() <= 1e-12 * f0, "F₀ = kA₀/Q at resonance");
        }
        let de = cf.energy_dissipated - o.energy_dissipated;
        let want = PI * k / q * omega * s2 - PI * a * phi.sin() * off;
        assert!(rel(de, want, scale) <= 1e-8, "{name}: E_cf − E_dis");
        let dv = o.virial - cf.virial;
        let want = k * mean * mean
            + 0.5 * k * (s1 - omega * omega * s2)
            + 0.5 * k * (1.0 - omega * omega) * a * a
            - 0.5 * a * phi.cos() * off;
        assert!(rel(dv, want, v_scale) <= 1e-8, "{name}: V − V_cf");
        if let (true, ContactLaw::Dmt { hamaker, .. }) = (name.contains("attractive"), law) {
            // van der Waals only: the largest attraction −H̃/d² is at the closest approach
            // (located separately on F_c and on V_T)
            assert_eq!(o.contact_fraction, 0.0);
            let f = -hamaker / o.min_distance.powi(2);
            assert!(
                rel(o.min_force, f, f.abs()) <= 1e-10,
                "{name}: {} vs {f}",
                o.min_force
            );
        }
        if let Some(rep) = repulsive {
            assert_eq!(
                o.phase < FRAC_PI_2,
                rep,
                "{name}: φ = {}°",
                o.phase.to_degrees()
            );
            assert_eq!(o.virial < 0.0, rep, "{name}: V = {}", o.virial);
        }
        println!(
            "{name:17} Ω = {omega}: A = {a:.5}, φ = {:7.3}°, contact {:.3}, THD {:.2e}, \
             E_dis = {:.6e} (balance {e_err:.1e}), E_cf off by {:+.2e} rel ({:+.2e} of πF₀A sin φ); \
             V = {:.6e} (balance {v_err:.1e}), V_cf off by {:+.2e} rel",
            phi.to_degrees(),
            o.contact_fraction,
            o.thd,
            o.energy_dissipated,
            (cf.energy_dissipated - o.energy_dissipated) / o.energy_dissipated,
            (cf.energy_dissipated - o.energy_dissipated) / input,
            o.virial,
            (cf.virial - o.virial) / o.virial,
        );
    }
}

/// Impact law (r = 0.8, 0.2, 0 and 0 with sticking on a pre-loaded sample, α5 < 0): the impulses
/// enter E_dis (the kinetic-energy loss ½(1 − r²) m_eff V̇², Brogliato 2016 §4.2) and the virial
/// (P z at the impact); the same exact period balances hold to 1e-8 of the largest term; the
/// peak sticking force is that of the static balance.
#[test]
fn point_mass_impacts_obey_the_balances() {
    for (r, alpha5) in [(0.8, 0.7), (0.2, 0.3), (0.0, 0.4), (0.0, -0.05)] {
        impact_balances(r, alpha5);
    }
}

fn impact_balances(r: f64, alpha5: f64) {
    let p = point_mass(ContactLaw::Impact { restitution: r }, 1.0, alpha5);
    let model = CantileverModel::new(&p).unwrap();
    let z0 = orbit(&model, 1);
    let o = observe(&model, &z0, 1, 10);
    let (a, phi, f0, q) = (o.amplitude, o.phase, p.alpha2, 1.0 / p.alpha3);
    let (input, damping) = (PI * f0 * a * phi.sin(), PI / q * (a * a + o.higher_n2_sq));
    let e_err = rel(
        o.energy_dissipated,
        input - damping,
        input.abs().max(damping.abs()),
    );
    let terms = [
        o.mean_deflection.powi(2),
        0.5 * (o.higher_sq - o.higher_n2_sq),
        -0.5 * f0 * a * phi.cos(),
    ];
    let v_scale = terms.iter().fold(0.0f64, |m, t| m.max(t.abs()));
    let v_err = rel(o.virial, terms.iter().sum(), v_scale);
    println!(
        "impact r = {r}, α5 = {alpha5}: {} impacts/period, contact {:.3}, peak λ {:.4e}, E_dis = {:.6e} (loss {:.6e}, balance {e_err:.1e}), \
         V = {:.6e} (balance {v_err:.1e}), φ = {:.3}°",
        o.impacts_per_period,
        o.contact_fraction,
        o.peak_force,
        o.energy_dissipated,
        o.impact_loss,
        o.virial,
        o.phase.to_degrees()
    );
    assert!(o.impacts_per_period >= 1.0);
    if alpha5 < 0.0 {
        // sticking on the sample at z = −α5: λ = z − α2 cos Ωτ (the equation of motion with
        // z' = z'' = 0), largest at Ωτ = π inside the sticking phase
        assert!(o.contact_fraction > 0.0);
        let peak = -alpha5 + p.alpha2;
        assert!(
            rel(o.peak_force, peak, peak) <= 1e-9,
            "peak λ {} vs {peak}",
            o.peak_force
        );
    }
    // no dissipation outside the impacts: free flight has no force, sticking no motion
    assert!(rel(o.energy_dissipated, o.impact_loss, o.impact_loss) <= 1e-9);
    assert!(e_err <= 1e-8, "energy balance off by {e_err:e}");
    assert!(v_err <= 1e-8, "virial balance off by {v_err:e}");
}

/// Beam N = 3 (the paper's eq. 26 set, α1 = 0.1) at Ω = 2.8 on its periodic orbit (linear law:
/// period 2, exact propagator; Hertz law: adaptive integrator at 1e-14): the per-mode energy
/// balances close (Σ|residual| ≤ 1e-9 of the largest term), Σ coupling = 0 over the orbit's
/// period, and the totals agree with the independent energy bookkeeping of `trajectory::record`
/// (beam damping; sample dissipation ∫α6 V̇_T² = E_dis since the elastic part returns over each
/// contact).
#[test]
fn beam_mode_balance_closes() {
    for law in [ContactLaw::Linear, ContactLaw::Hertz] {
        beam_mode_balance(law);
    }
}

fn beam_mode_balance(law: ContactLaw) {
    let p = Params {
        omega: 2.8,
        contact_law: law,
        ..Params::default()
    };
    let model = CantileverModel::new(&p).unwrap();
    let mut it = build(&model, integ(), 0.0, &model.rest()).unwrap();
    let s = steady_state(it.as_mut(), &SteadyOptions::default()).unwrap();
    let Motion::Periodic { period: n } = s.motion else {
        panic!("expected a periodic orbit, got {:?}", s.motion)
    };
    let guess = s.end_state().clone();
    let period = ShootingOptions::default().with_period(n);
    let orbit = shoot(&mut StroboscopicMap::new(it.as_mut(), 1), &guess, &period).unwrap();
    let z0 = orbit.state.clone();
    let o = observe_orbit(&model, integ(), &orbit, 10).unwrap();
    assert_eq!(o.periods, n);
    let big = o
        .mode_balance
        .iter()
        .flat_map(|m| [m.drive, m.beam_damping, m.sample, m.coupling])
        .fold(0.0f64, |x, v| x.max(v.abs()));
    let residual: f64 = o.mode_balance.iter().map(|m| m.residual.abs()).sum();
    let coupling: f64 = o.mode_balance.iter().map(|m| m.coupling).sum();
    for m in &o.mode_balance {
        println!("{law}: {m:?}");
    }
    println!(
        "{law}, period {n}: Σ|residual| = {residual:.2e}, Σ coupling = {coupling:.2e}, \
         largest term {big:.4e}"
    );
    println!(
        "{law}: beam closed forms (mode-1 point mass k̃ = {:.4}, Q₁ = {:.3}, A₀ = {:.4}): \
         E_cf = {:.6e} vs E_dis = {:.6e}, V_cf = {:.6e} vs V = {:.6e}",
        o.closed_form.stiffness,
        o.closed_form.quality_factor,
        o.closed_form.free_amplitude,
        o.closed_form.energy_dissipated,
        o.energy_dissipated,
        o.closed_form.virial,
        o.virial
    );
    assert_eq!(o.mode_balance.len(), 3);
    assert!(residual <= 1e-9 * big, "{law}: residual {residual:e}");
    assert!(coupling.abs() <= 1e-9 * big, "{law}: coupling {coupling:e}");
    assert!(o.contact_fraction > 0.0);
    // trajectory::record from the same start over the same window
    let mut it = build(&model, integ(), 0.0, &z0).unwrap();
    let spec = RecordSpec {
        transient_periods: 0.0,
        record_tau: n as f64 * model.period(),
        samples_per_period: 0,
        energy: true,
        body_contact: false,
    };
    let tr = record(it.as_mut(), &spec).unwrap();
    let damping: f64 = tr.energy.iter().map(|e| e.beam_dissipation).sum::<f64>() / n as f64;
    let sample: f64 = tr.energy.iter().map(|e| e.contact_dissipation).sum::<f64>() / n as f64;
    let ours: f64 = o.mode_balance.iter().map(|m| m.beam_damping).sum();
    println!(
        "{law}: vs trajectory::record: beam damping {:.1e}, E_dis {:.1e} relative",
        rel(ours, damping, damping),
        rel(o.energy_dissipated, sample, sample)
    );
    assert!(rel(ours, damping, damping) <= 1e-9, "{ours} vs {damping}");
    assert!(
        rel(o.energy_dissipated, sample, sample) <= 1e-9,
        "{} vs {sample}",
        o.energy_dissipated
    );
}

/// Independent checks, point mass with the linear law without damper (α6 = 0): the contact
/// fraction from the located switching times of a separate run; THD and Σ_{n≥2}Aₙ² by Parseval
/// against the sum of 200 listed harmonics (force continuous, so Aₙ ~ n⁻⁴); the mean deflection
/// against ⟨F_c⟩ (period average of z'' + α3 z' + z = α2 cos Ωτ + F_c with k = 1); the peak force
/// α4 × indentation (F_c = α4 δ, located separately on F_c and on V_T); min distance = −δ_max;
/// a window starting at 0.37 T on the orbit gives the same observables (to 1e-10).
#[test]
fn thd_mean_and_contact_fraction_agree_with_independent_checks() {
    let mut p = point_mass(ContactLaw::Linear, 1.0, 0.6);
    p.alpha6 = 0.0;
    let model = CantileverModel::new(&p).unwrap();
    let z0 = orbit(&model, 1);
    let o = observe(&model, &z0, 1, 200);
    let t = model.period();
    let mut it = build(&model, IntegratorOptions::default(), 0.0, &z0).unwrap();
    let events = events_until(it.as_mut(), t);
    // the same window started inside the period (τ₀ = 0.37 T on the orbit) sees the same orbit
    let tau0 = 0.37 * t;
    let mut it2 = build(&model, integ(), 0.0, &z0).unwrap();
    advance_dyn(it2.as_mut(), tau0, &mut |_, _, _| Ok(())).unwrap();
    let shifted = observe_from(
        &model,
        integ(),
        tau0,
        it2.state(),
        &ObservableOptions::default(),
    )
    .unwrap();
    for (x, y) in [
        (shifted.amplitude, o.amplitude),
        (shifted.phase, o.phase),
        (shifted.mean_deflection, o.mean_deflection),
        (shifted.virial, o.virial),
        (shifted.contact_fraction, o.contact_fraction),
        (shifted.peak_force, o.peak_force),
        (shifted.min_distance, o.min_distance),
    ] {
        assert!(
            rel(x, y, y.abs()) <= 1e-10,
            "window from 0.37 T: {x} vs {y}"
        );
    }
    let mut region = model.region_at(0.0, &z0);
    let (mut last, mut contact) = (0.0, 0.0);
    for e in &events {
        if region == Region::Contact {
            contact += e.tau - last;
        }
        (last, region) = (e.tau, e.to);
    }
    if region == Region::Contact {
        contact += t - last;
    }
    assert_eq!(events.len(), 2);
    assert!(rel(o.contact_fraction, contact / t, 1.0) <= 1e-12);
    assert!(rel(o.contact_time, contact, t) <= 1e-12);
    assert_eq!(o.impacts_per_period, 1.0);
    let listed: f64 = o.harmonics[1..].iter().map(|h| h.amplitude.powi(2)).sum();
    assert!(
        rel(listed, o.higher_sq, o.higher_sq) <= 1e-8,
        "{listed} vs {}",
        o.higher_sq
    );
    assert!(rel(o.thd, listed.sqrt() / o.amplitude, o.thd) <= 1e-8);
    assert!(rel(o.mean_deflection, o.mean_force, o.mean_force.abs()) <= 1e-10);
    assert!(rel(o.peak_force, p.alpha4 * o.indentation, o.peak_force) <= 1e-12);
    assert_eq!(o.min_distance, -o.indentation);
    assert!(o.min_force <= 0.0 && o.min_force >= -1e-12 * o.peak_force);
    println!(
        "linear α6 = 0: contact fraction {:.6}, THD {:.4e}, ⟨z⟩ = {:.6e}, peak force {:.6e}",
        o.contact_fraction, o.thd, o.mean_deflection, o.peak_force
    );
}

/// periods = 0 and harmonics = 0 are refused with an error naming the field.
#[test]
fn bad_options_are_typed_errors() {
    let model = CantileverModel::new(&point_mass(ContactLaw::Linear, 1.0, 1.0)).unwrap();
    for (opts, field) in [
        (
            ObservableOptions {
                periods: 0,
                harmonics: 10,
            },
            "periods",
        ),
        (
            ObservableOptions {
                periods: 1,
                harmonics: 0,
            },
            "harmonics",
        ),
    ] {
        let err = observe_from(
            &model,
            IntegratorOptions::default(),
            0.0,
            &model.rest(),
            &opts,
        )
        .unwrap_err();
        assert!(
            matches!(err, SimError::OutOfRange { name, .. } if name == field),
            "{err}"
        );
    }
}

/// `report::observables` carries every field under its name (the JSON shared by the command line
/// and Python), with one balance per mode and non-finite values as null.
#[test]
fn report_document_has_every_field() {
    let p = point_mass(ContactLaw::Linear, 1.0, 0.6);
    let model = CantileverModel::new(&p).unwrap();
    let o = observe(&model, &harmonic_response(&model, Region::Free, 0.0), 1, 4);
    let doc = report::observables(&o);
    assert_eq!(doc["amplitude"].as_f64(), Some(o.amplitude));
    assert_eq!(doc["phase"].as_f64(), Some(o.phase));
    assert_eq!(doc["energy_dissipated"].as_f64(), Some(o.energy_dissipated));
    assert_eq!(doc["harmonics"].as_array().map(Vec::len), Some(4));
    assert_eq!(doc["mode_balance"].as_array().map(Vec::len), Some(1));
    assert_eq!(
        doc["closed_form"]["quality_factor"].as_f64(),
        Some(o.closed_form.quality_factor)
    );
    let mut inf = o.clone();
    inf.closed_form.quality_factor = f64::INFINITY;
    assert!(report::observables(&inf)["closed_form"]["quality_factor"].is_null());
}

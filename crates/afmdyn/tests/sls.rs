//! The standard linear solid (Zener) sample with surface memory ([`ContactLaw::Sls`]; López-Guerra
//! & Solares, *Beilstein J. Nanotechnol.* 5 (2014) 2149): the Maxwell arm's loss under a
//! prescribed harmonic indentation against its closed form (Lakes, *Viscoelastic Materials*, CUP
//! 2009, §2.7); the free surface's exponential recovery; the tip leaving where the sample's force
//! vanishes and meeting the recovering surface again; on an orbit, the energy the tip loses equal
//! to the dashpot's dissipation and the energy balance closed; the flow against an independent
//! integrator written here; κ → 0 against the linear law without damper; typed refusals; and the
//! SI probe's groups.

use afmdyn::analysis::observables::{observe, ObservableOptions};
use afmdyn::analysis::shooting::{shoot, ShootingOptions};
use afmdyn::contact::Zener;
use afmdyn::galerkin::Region;
use afmdyn::integrate::{advance, build, IntegratorKind, IntegratorOptions};
use afmdyn::maps::StroboscopicMap;
use afmdyn::probe::Probe;
use afmdyn::trajectory::{record, RecordSpec};
use afmdyn::{CantileverModel, ContactLaw, Params, SimError};
use nalgebra::DVector;
use std::f64::consts::PI;

use super::common;
use common::events_until;

fn sls(kappa: f64) -> ContactLaw {
    ContactLaw::Sls {
        maxwell_stiffness: kappa,
    }
}

fn model(kappa: f64, modes: usize, omega: f64) -> CantileverModel {
    CantileverModel::new(&Params {
        modes,
        omega,
        contact_law: sls(kappa),
        ..Params::default()
    })
    .unwrap()
}

fn adaptive(tol: f64) -> IntegratorOptions {
    IntegratorOptions {
        kind: IntegratorKind::Adaptive,
        tolerance: tol,
        ..Default::default()
    }
}

/// A prescribed indentation δ(τ) = δ̄ + δ₀ sin ωτ held in contact: the law's own rate u̇ and
/// dissipation α6 u̇² ([`Zener`]) integrated here (RK4 on u and the dissipated energy, 4000 steps
/// per cycle, 40 cycles of transient) dissipate per cycle the Maxwell element's
/// πκωτ_r δ₀²/(1 + ω²τ_r²), τ_r = α6/κ (Lakes 2009, §2.7), to 1e-9, at ωτ_r = 0.1, 1 and 10;
/// and the work the indenter does, ∮F dδ, is the same energy (the springs store none over a
/// cycle).
#[test]
fn prescribed_harmonic_indentation_dissipates_the_maxwell_loss() {
    let zn = Zener::new(20.0, 20.0, 0.2);
    let tau_r = 0.2 / 20.0;
    for wt in [0.1, 1.0, 10.0] {
        let omega = wt / tau_r;
        let (mean, amp) = (0.2, 0.1);
        let delta = |t: f64| mean + amp * (omega * t).sin();
        let delta_dot = |t: f64| amp * omega * (omega * t).cos();
        // y = (u, dissipated, work)
        let f = |t: f64, y: [f64; 3]| {
            let d = delta(t);
            [
                zn.rate(true, d, y[0]),
                zn.dissipation(true, d, y[0]),
                zn.force(true, d, y[0]) * delta_dot(t),
            ]
        };
        let period = 2.0 * PI / omega;
        let steps = 4000;
        let h = period / steps as f64;
        let mut y = [mean, 0.0, 0.0];
        let mut t = 0.0;
        for cycle in 0..41 {
            if cycle == 40 {
                y[1] = 0.0;
                y[2] = 0.0;
            }
            for _ in 0..steps {
                let add = |a: [f64; 3], b: [f64; 3], s: f64| {
                    [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]]
                };
                let k1 = f(t, y);
                let k2 = f(t + h / 2.0, add(y, k1, h / 2.0));
                let k3 = f(t + h / 2.0, add(y, k2, h / 2.0));
                let k4 = f(t + h, add(y, k3, h));
                for i in 0..3 {
                    y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
                }
                t += h;
            }
        }
        // the closed form, written here
        let want = PI * 20.0 * wt * amp * amp / (1.0 + wt * wt);
        assert!(
            (y[1] / want - 1.0).abs() < 1e-9,
            "ωτ_r = {wt}: {} vs {want}",
            y[1]
        );
        assert!(
            (y[2] / want - 1.0).abs() < 1e-9,
            "ωτ_r = {wt}: work {} vs {want}",
            y[2]
        );
        assert!((zn.cycle_dissipation(omega, amp) / want - 1.0).abs() < 1e-14);
    }
}

/// Out of the tip's reach the dented surface recovers as u(τ) = u₀ e^{−α4κτ/(α6(α4 + κ))} (the
/// springs balanced through the dashpot), to 1e-10 relative, while the beam's free response is
/// untouched (the sample exerts no force on a tip above it).
#[test]
fn the_free_surface_recovers_exponentially() {
    let m = CantileverModel::new(&Params {
        alpha5: 5.0,
        contact_law: sls(20.0),
        ..Params::default()
    })
    .unwrap();
    let mut z0 = common::harmonic_response(&m, Region::Free, 0.0);
    let u0 = 0.3;
    z0[2 * m.modes()] = u0;
    let mut it = build(&m, adaptive(1e-13), 0.0, &z0).unwrap();
    // over 2.5 recovery times
    let t1 = 0.05;
    assert!(events_until(it.as_mut(), t1).is_empty());
    let rate = 20.0 * 20.0 / (0.2 * 40.0);
    let want = u0 * (-rate * t1).exp();
    let got = it.state()[2 * m.modes()];
    assert!((got / want - 1.0).abs() < 1e-10, "u {got} vs {want}");
    let beam = common::harmonic_response(&m, Region::Free, t1);
    let err = (it.state().rows(0, 2 * m.modes()) - beam.rows(0, 2 * m.modes())).amax();
    assert!(err < 1e-11, "beam {err:e}");
}

/// On the stable period-1 orbit (N = 2, Ω = 3): the tip leaves where the sample's force falls to
/// 0 and touches down where V_T = −s(u) (the recovering surface), the contact force never pulls,
/// the observables' peak force bounds the sampled maximum,
/// the energy the tip loses per period (−∮F dV_T, [`observe`]) equals the dashpot's dissipation
/// booked by the recorded trajectory (∮α6 u̇² dτ, in and out of contact) to 1e-8, and the
/// energy balance of each period closes to 1e-9 of the drive's work.
#[test]
fn an_orbit_loses_to_the_dashpot_what_the_tip_loses() {
    let m = model(20.0, 2, 3.0);
    let n = m.modes();
    let zn = *m.zener().unwrap();
    let mut it = build(&m, IntegratorOptions::default(), 0.0, &m.rest()).unwrap();
    advance(it.as_mut(), 300.0 * m.period()).unwrap();
    let mut fresh = build(&m, IntegratorOptions::default(), 0.0, &m.rest()).unwrap();
    let map = &mut StroboscopicMap::new(fresh.as_mut(), 1);
    let o = shoot(map, it.state(), &ShootingOptions::default()).unwrap();
    assert!(o.stable);
    assert_eq!(o.state.len(), 2 * n + 1);
    let mut it = build(&m, IntegratorOptions::default(), 0.0, &o.state).unwrap();
    let obs = observe(it.as_mut(), &ObservableOptions::default()).unwrap();
    assert!(obs.energy_dissipated > 0.0);
    let mut it = build(&m, IntegratorOptions::default(), 0.0, &o.state).unwrap();
    let spec = RecordSpec {
        transient_periods: 0.0,
        record_tau: 3.0 * m.period(),
        samples_per_period: 400,
        energy: true,
        body_contact: false,
    };
    let tr = record(it.as_mut(), &spec).unwrap();
    assert_eq!(tr.events.len(), 6);
    for ev in &tr.events {
        let u = ev.state[2 * n];
        let v = m.v_t(ev.tau, &ev.state);
        if ev.to == Region::Free {
            // F = α4 δ + κ(δ − u) = 0 at δ = −V_T
            let f = zn.force(true, -v, u);
            assert!(f.abs() < 1e-9, "force {f:e} where the tip leaves");
            assert!(u > 0.0, "the surface is dented when the tip leaves");
        } else {
            assert!(
                (v + zn.surface(u)).abs() < 1e-10,
                "touch-down off the surface"
            );
        }
    }
    let peak = tr
        .samples
        .iter()
        .map(|s| s.contact_force)
        .fold(0.0, f64::max);
    for s in &tr.samples {
        assert!(
            s.contact_force > -1e-9 * peak,
            "the sample pulls: {}",
            s.contact_force
        );
    }
    // the observables' peak force (located where dF/dτ = (α4 + κ)δ̇ − κu̇ vanishes) is the
    // sampled maximum's upper bound, and close to it (400 samples per period)
    let rel = obs.peak_force / peak - 1.0;
    assert!(
        (-1e-12..1e-4).contains(&rel),
        "peak {} vs sampled {peak}",
        obs.peak_force
    );
    for b in &tr.energy {
        let res = b.residual();
        assert!(res.abs() < 1e-9 * b.base_work.abs(), "residual {res:e}");
        let booked = b.contact_dissipation;
        assert!(
            (booked / obs.energy_dissipated - 1.0).abs() < 1e-8,
            "{booked} vs {}",
            obs.energy_dissipated
        );
    }
}

/// The model written again here for N modes (eqs. 11–14, `common::FreeBeam`, with the SLS force
/// at the tip and the dashpot's extension u), integrated by `common::rk4_switched_flow`.
struct Independent {
    beam: common::FreeBeam,
    p: Params,
    kappa: f64,
}

impl Independent {
    fn new(m: &CantileverModel, kappa: f64) -> Self {
        Independent {
            beam: common::FreeBeam::of(m),
            p: *m.params(),
            kappa,
        }
    }
    fn v_t(&self, tau: f64, z: &DVector<f64>) -> f64 {
        self.beam.v_t(tau, z).0
    }
    /// V_T + κu/(α4 + κ): the tip's height over the (recovering) surface.
    fn gap(&self, tau: f64, z: &DVector<f64>) -> f64 {
        let n = self.p.modes;
        self.v_t(tau, z) + self.kappa * z[2 * n] / (self.p.alpha4 + self.kappa)
    }
    fn rhs(&self, contact: bool, tau: f64, z: &DVector<f64>) -> DVector<f64> {
        let n = self.p.modes;
        let (k1, k2, eta) = (self.p.alpha4, self.kappa, self.p.alpha6);
        let u = z[2 * n];
        let delta = -self.v_t(tau, z);
        let (force, surface) = if contact {
            (k1 * delta + k2 * (delta - u), delta)
        } else {
            (0.0, k2 * u / (k1 + k2))
        };
        let mut out = self.beam.rhs(tau, z, force, 2 * n + 1);
        out[2 * n] = k2 / eta * (surface - u);
        out
    }
    /// z(t1) from z0 by RK4 with `steps_per_period` steps, the switchings (V_T + s(u) = 0: the
    /// contact's force F = −(α4 + κ)(V_T + s(u)) vanishing, or the tip meeting the surface)
    /// located by bisection (`common::rk4_switched_flow`).
    fn flow(&self, z0: &DVector<f64>, t1: f64, steps_per_period: usize) -> DVector<f64> {
        common::rk4_switched_flow(
            &|contact, tau, z| self.rhs(contact, tau, z),
            &|tau, z| self.gap(tau, z) < 0.0,
            z0,
            t1,
            self.p.period() / steps_per_period as f64,
        )
    }
}

/// The flow over 12 drive periods from rest (N = 3 at the default Ω = 2.6: a transient with
/// taps on a recovering surface) agrees with the independent integrator to 1e-8.
#[test]
fn the_flow_agrees_with_an_independent_integrator() {
    let m = model(20.0, 3, 2.6);
    let t1 = 12.0 * m.period();
    let mut it = build(&m, adaptive(1e-13), 0.0, &m.rest()).unwrap();
    let ev = events_until(it.as_mut(), t1);
    assert!(ev.len() >= 10, "{} events", ev.len());
    let ind = Independent::new(&m, 20.0).flow(&m.rest(), t1, 20000);
    let d = (it.state() - &ind).amax();
    assert!(d < 1e-8, "differs by {d:e}");
}

/// κ → 0: the Maxwell arm vanishes and the sample is the linear law without its damper (the
/// exact propagator): the stroboscopic states after 10 periods from rest agree to O(κ).
#[test]
fn a_vanishing_maxwell_arm_is_the_linear_law_without_damper() {
    let kappa = 1e-7;
    let m = model(kappa, 2, 2.6);
    let lin = CantileverModel::new(&Params {
        modes: 2,
        alpha6: 0.0,
        ..Params::default()
    })
    .unwrap();
    let t1 = 10.0 * m.period();
    let mut a = build(&m, adaptive(1e-13), 0.0, &m.rest()).unwrap();
    advance(a.as_mut(), t1).unwrap();
    let mut b = build(&lin, IntegratorOptions::default(), 0.0, &lin.rest()).unwrap();
    advance(b.as_mut(), t1).unwrap();
    let d = (a.state().rows(0, 4) - b.state()).amax();
    assert!(d < 1e-5 && d > 0.0, "differs by {d:e}");
}

/// Refusals: κ ≤ 0 (named maxwell_stiffness), α6 = 0 (the dashpot), α4 = 0 (nothing brings the
/// surface back), and every integrator but the adaptive one, each a typed error; a state of
/// 2N entries where 2N + 1 are needed.
#[test]
fn refusals_are_typed_and_named() {
    let new = |p: Params| {
        CantileverModel::new(&p)
            .map(|_| ())
            .unwrap_err()
            .to_string()
    };
    let base = Params {
        contact_law: sls(20.0),
        ..Params::default()
    };
    assert!(new(Params {
        contact_law: sls(0.0),
        ..base
    })
    .contains("maxwell_stiffness"));
    assert!(new(Params {
        contact_law: sls(-1.0),
        ..base
    })
    .contains("maxwell_stiffness"));
    assert!(new(Params {
        alpha6: 0.0,
        ..base
    })
    .contains("alpha6"));
    assert!(new(Params {
        alpha4: 0.0,
        ..base
    })
    .contains("alpha4"));
    let m = CantileverModel::new(&base).unwrap();
    for kind in [
        IntegratorKind::Exact,
        IntegratorKind::Split,
        IntegratorKind::Taylor,
        IntegratorKind::Rk4,
    ] {
        let e = build(
            &m,
            IntegratorOptions {
                kind,
                ..Default::default()
            },
            0.0,
            &m.rest(),
        )
        .map(|_| ())
        .unwrap_err();
        assert!(
            matches!(e, SimError::Unsupported { law: "sls", .. }),
            "{kind:?}: {e}"
        );
    }
    let e = build(&m, IntegratorOptions::default(), 0.0, &DVector::zeros(6))
        .map(|_| ())
        .unwrap_err();
    assert!(
        matches!(e, SimError::StateLength { expected: 7, .. }),
        "{e}"
    );
}

/// The probe's SI keys: α4 = k₁g₀/F_s, κ = k₂g₀/F_s, α6 = κτ_r/t_s (the dashpot η = k₂τ_r as
/// the linear law's damper); a missing key is named.
#[test]
fn the_probe_maps_the_springs_and_the_relaxation_time() {
    let text = |sample: &str| {
        format!(
            "model = \"point-mass\"\n[cantilever]\nspring_constant = 2\nresonance_frequency = \
             70e3\nquality_factor = 200\n[sample]\nlaw = \"sls\"\n{sample}\n[drive]\n\
             free_amplitude = 10e-9\n"
        )
    };
    let p = Probe::parse(
        &text("stiffness = 0.5\nmaxwell_stiffness = 1.5\nrelaxation_time = 20e-6"),
        "<test>",
    )
    .unwrap();
    let (g0, f, t) = (p.scales.length_m, p.scales.force_n, p.scales.time_s);
    let ContactLaw::Sls { maxwell_stiffness } = p.params.contact_law else {
        panic!("{:?}", p.params.contact_law)
    };
    assert!((p.params.alpha4 / (0.5 * g0 / f) - 1.0).abs() < 1e-12);
    assert!((maxwell_stiffness / (1.5 * g0 / f) - 1.0).abs() < 1e-12);
    assert!((p.params.alpha6 / (maxwell_stiffness * 20e-6 / t) - 1.0).abs() < 1e-12);
    for (sample, key) in [
        (
            "maxwell_stiffness = 1.5\nrelaxation_time = 20e-6",
            "stiffness",
        ),
        (
            "stiffness = 0.5\nrelaxation_time = 20e-6",
            "maxwell_stiffness",
        ),
        (
            "stiffness = 0.5\nmaxwell_stiffness = 1.5",
            "relaxation_time",
        ),
        (
            "stiffness = 0.5\nmaxwell_stiffness = 1.5\nrelaxation_time = -1",
            "relaxation_time",
        ),
    ] {
        let e = Probe::parse(&text(sample), "<test>")
            .unwrap_err()
            .to_string();
        assert!(e.contains(key), "{e}");
    }
}

//! The capillary law (`--contact-law capillary`, probe `law = "capillary"`): a water meniscus
//! formed when the tip touches the sample and ruptured on retraction at a distance set by its
//! volume (the tapping-mode mechanism of Zitzler, Herminghaus & Mugele, *Phys. Rev. B* 66
//! (2002) 155436), over a Hertz sample. Checked against:
//!
//! * the sphere–flat meniscus force at contact, −4πRγcosθ (Israelachvili, *Intermolecular and
//!   Surface Forces*, 3rd ed. 2011, §17.7), in SI from a probe;
//! * at a distance D, the force of a meniscus of fixed volume computed here from its
//!   definition: the immersion d solving V = ∫₀^{r₁} 2πr (D + r²/(2R)) dr, r₁² = 2Rd, by
//!   bisection, and the Laplace pressure 2γcosθ/(D + d) over πr₁² (Butt & Kappl, *Adv. Colloid
//!   Interface Sci.* 146 (2009) 48, §3.1);
//! * the rupture distance (1 + θ/2)V^{1/3} (Lian, Thornton & Adams, *J. Colloid Interface Sci.*
//!   161 (1993) 138);
//! * the energy per tap E_cap = ∫₀^{D_r} |F| dD in closed form against a Gauss–Legendre
//!   quadrature of the law's force, and on a periodic orbit without viscous damping the
//!   observables' E_dis (−∮F ḋ) and the recorded energy balance;
//! * the hysteresis of the region: formed at V_T = 0, ruptured at V_T = D̃_r, and a start in
//!   between decided by the direction of motion;
//! * bad meniscus input refused naming the key.

use afmdyn::contact::{Meniscus, TipSample, TipSampleLaw};
use afmdyn::integrate::{advance, build, IntegratorKind, IntegratorOptions};
use afmdyn::maps::flow::flow;
use afmdyn::probe::Probe;
use afmdyn::{CantileverModel, ContactLaw, HybridSystem, Params, Region};
use nalgebra::{DMatrix, DVector};
use std::f64::consts::PI;

use super::common;
use common::{gauss_legendre, hysteretic_tap};

/// A 40 N/m lever with a 10 nm tip over a polymer in humid air: a 1e-25 m³ water meniscus
/// (rupture at ≈ 5 nm), contact angle 20°.
const R: f64 = 10e-9;
const V: f64 = 1e-25;
const GAMMA: f64 = 0.072;
const THETA_DEG: f64 = 20.0;

fn probe_with(sample: &str) -> Result<Probe, String> {
    let text = format!(
        "model = \"point-mass\"\n[cantilever]\nspring_constant = 40\nresonance_frequency = \
         300e3\nquality_factor = 400\n[tip]\nradius = {R}\n[sample]\nlaw = \"capillary\"\n\
         youngs_modulus = 1e9\npoisson_ratio = 0.3\n{sample}\nz_c = 8e-9\n[drive]\n\
         free_amplitude = 10e-9\n"
    );
    Probe::parse(&text, "<test>").map_err(|e| e.to_string())
}

fn probe() -> Probe {
    probe_with(&format!(
        "meniscus_volume = {V}\nsurface_tension = {GAMMA}\ncontact_angle = {THETA_DEG}"
    ))
    .unwrap()
}

fn law_of(p: &Params) -> TipSample {
    TipSample {
        law: p.contact_law,
        stiffness: p.alpha4,
        damping: p.alpha6,
    }
}

/// The meniscus force at distance `d` (m) computed from the volume constraint (module docs).
fn force_from_volume(d: f64) -> f64 {
    let theta = THETA_DEG.to_radians();
    let volume = |imm: f64| {
        // ∫₀^{r₁} 2πr (D + r²/(2R)) dr with r₁² = 2R·imm
        let r1sq = 2.0 * R * imm;
        PI * r1sq * d + PI * r1sq * r1sq / (4.0 * R)
    };
    let (mut lo, mut hi) = (0.0, R);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if volume(mid) < V {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let imm = 0.5 * (lo + hi);
    let pressure = 2.0 * GAMMA * theta.cos() / (d + imm);
    -pressure * PI * 2.0 * R * imm
}

/// In SI from the probe: −4πRγcosθ at contact, the volume-constrained meniscus force at
/// distances up to rupture, and the rupture distance (1 + θ/2)V^{1/3}.
#[test]
fn forces_and_rupture_are_the_meniscus_closed_forms() {
    let p = probe();
    let (g0, f_unit) = (p.scales.length_m, p.scales.force_n);
    let ts = law_of(&p.params);
    let theta = THETA_DEG.to_radians();
    let rel = |got: f64, want: f64| (got / want - 1.0).abs();
    let at_contact = ts.force(true, 0.0, 0.0).force * f_unit;
    let want = -4.0 * PI * R * GAMMA * theta.cos();
    assert!(rel(at_contact, want) < 1e-12, "{at_contact} vs {want}");
    assert!(rel(force_from_volume(0.0), want) < 1e-12);
    let rupture = p.params.contact_law.release_distance(p.params.alpha4) * g0;
    let want_r = (1.0 + 0.5 * theta) * V.cbrt();
    assert!(rel(rupture, want_r) < 1e-12, "{rupture} vs {want_r}");
    for frac in [0.05, 0.3, 0.7, 0.999] {
        let d = frac * rupture;
        let got = ts.force(true, -d / g0, 0.0).force * f_unit;
        let want = force_from_volume(d);
        assert!(rel(got, want) < 1e-9, "D = {d}: {got} vs {want}");
        // no meniscus before contact: no force in free flight
        assert_eq!(ts.force(false, -d / g0, 0.0).force, 0.0);
    }
    // in contact the Hertz repulsion adds to the meniscus's constant pull
    let delta = 1e-9 / g0;
    let hertz = TipSample {
        law: ContactLaw::Hertz,
        stiffness: p.params.alpha4,
        damping: 0.0,
    };
    let both = ts.force(true, delta, 0.0).force;
    assert!((both - hertz.force(true, delta, 0.0).force - at_contact / f_unit).abs() < 1e-12);
}

/// E_cap = F̃_cap(D̃_r + h̃ − √(D̃_r² + h̃²)) against a composite 40-point Gauss–Legendre
/// quadrature of the law's own force over [0, D̃_r], and the contact region's potential drop at formation.
#[test]
fn energy_per_tap_is_the_closed_form() {
    for (capillary, meniscus, rupture) in [
        (0.1f64, 0.01f64, 0.05f64),
        (2.0, 0.3, 0.1),
        (1e-3, 1e-3, 2.0),
    ] {
        let men = Meniscus::new(capillary, meniscus, rupture);
        // panels [0, h̃], [h̃, 2h̃], [2h̃, 4h̃], … up to D̃_r: the force varies on the scale h̃
        let rule = gauss_legendre(40);
        let mut edges = vec![0.0, meniscus.min(rupture)];
        while *edges.last().unwrap() < rupture {
            let next = (2.0 * edges.last().unwrap()).min(rupture);
            edges.push(next);
        }
        let quad: f64 = edges
            .windows(2)
            .map(|p| {
                let (a, b) = (p[0], p[1]);
                rule.iter()
                    .map(|&(x, w)| {
                        let d = a + 0.5 * (b - a) * (x + 1.0);
                        -0.5 * (b - a) * w * men.force(d).0
                    })
                    .sum::<f64>()
            })
            .sum();
        let closed = men.hysteresis();
        assert!((closed / quad - 1.0).abs() < 1e-10, "{closed} vs {quad}");
        let ts = TipSample {
            law: ContactLaw::Capillary {
                capillary,
                meniscus,
                rupture,
            },
            stiffness: 20.0,
            damping: 0.0,
        };
        // the potential is 0 where the meniscus ruptures and −E_cap at contact
        assert!(ts.potential(true, -rupture).abs() < 1e-15 * closed.max(1.0));
        assert!((ts.potential(true, 0.0) + closed).abs() < 1e-14 * closed.max(1.0));
    }
}

/// The dimensionless beam (N = 2, Ω = 2.8, the default meniscus) without viscous damping in the
/// sample.
fn tapping_model() -> CantileverModel {
    CantileverModel::new(&Params {
        modes: 2,
        omega: 2.8,
        alpha6: 0.0,
        contact_law: ContactLaw::Capillary {
            capillary: 0.1,
            meniscus: 0.01,
            rupture: 0.05,
        },
        ..Params::default()
    })
    .unwrap()
}

/// On the period-1 orbit the meniscus forms once at V_T = 0 and ruptures once at V_T = D̃_r;
/// the observables' E_dis is E_cap (α6 = 0: the meniscus is the only loss in the sample), and
/// the recorded energy balance closes with E_cap booked per period; the monodromy matrix is
/// the flow's derivative (central differences).
#[test]
fn a_tap_dissipates_the_meniscus_energy() {
    let m = tapping_model();
    let state = hysteretic_tap(&m, Meniscus::new(0.1, 0.01, 0.05).hysteresis());
    // the monodromy (variational equations through the kink at V_T = 0, saltation matrices
    // where the meniscus forms and ruptures) against central differences of the flow
    let t1 = m.period();
    let opts = IntegratorOptions {
        kind: IntegratorKind::Adaptive,
        tolerance: 1e-13,
        ..IntegratorOptions::default()
    };
    let mut it = build(&m, opts, 0.0, &state).unwrap();
    let map = flow(it.as_mut(), 0.0, &state, t1, None, true).unwrap();
    let mut flow = |z: &DVector<f64>| {
        it.reset(0.0, z).unwrap();
        advance(it.as_mut(), t1).unwrap();
        it.state().clone()
    };
    let mut fd = DMatrix::zeros(4, 4);
    for k in 0..4 {
        let (mut zp, mut zm) = (state.clone(), state.clone());
        zp[k] += 1e-6;
        zm[k] -= 1e-6;
        fd.set_column(k, &((flow(&zp) - flow(&zm)) / 2e-6));
    }
    let err = (&map.jacobian - &fd).amax() / (1.0 + fd.amax());
    assert!(err < 1e-5, "monodromy vs finite differences: {err:e}");
}

/// A start with 0 < V_T < D̃_r is in the meniscus's region when the tip moves away from the
/// sample and free when it approaches.
#[test]
fn the_meniscus_band_is_decided_by_the_motion() {
    let m = tapping_model();
    assert_eq!(m.release_distance(), 0.05);
    let phi = m.tip()[0];
    for (rate, want) in [(1.0, Region::Contact), (-1.0, Region::Free)] {
        let mut z = DVector::zeros(4);
        z[0] = 0.025 / phi;
        z[2] = (rate - 0.1 * 2.8) / phi;
        assert_eq!(m.mode_at(0.0, z.as_slice()), want, "rate {rate}");
    }
}

/// Bad meniscus input: missing volume, a non-wetting angle, a meniscus wetting the tip beyond
/// its apex, a key of another law — each refused naming it.
#[test]
fn bad_meniscus_input_is_refused_naming_the_key() {
    let e = probe_with("").unwrap_err();
    assert!(e.contains("meniscus_volume"), "{e}");
    let e = probe_with(&format!("meniscus_volume = {V}\ncontact_angle = 95")).unwrap_err();
    assert!(e.contains("contact_angle") && e.contains("[0, 90)"), "{e}");
    let e = probe_with("meniscus_volume = 1e-24").unwrap_err();
    assert!(e.contains("meniscus_volume") && e.contains("R/2"), "{e}");
    let e = probe_with(&format!("meniscus_volume = {V}\nhamaker = 1e-19")).unwrap_err();
    assert!(e.contains("hamaker"), "{e}");
    let e = probe_with(&format!("meniscus_volume = {V}\nsurface_tension = -1")).unwrap_err();
    assert!(e.contains("surface_tension"), "{e}");
    // the defaults: water's surface tension, θ = 0
    let p = probe_with(&format!("meniscus_volume = {V}")).unwrap();
    let ContactLaw::Capillary { capillary, .. } = p.params.contact_law else {
        panic!("{:?}", p.params.contact_law)
    };
    let want = 4.0 * PI * R * afmdyn::probe::WATER_SURFACE_TENSION / p.scales.force_n;
    assert!((capillary / want - 1.0).abs() < 1e-12);
}

/// Laws of a gas are refused in a liquid `[medium]`: the capillary meniscus (it does not form
/// under water) and the electrostatic force across ε₀; in air both load.
#[test]
fn gas_laws_are_refused_in_a_liquid() {
    let water = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/probe-water-beam.toml"
    ))
    .unwrap();
    let dmt = "law = \"dmt\"\nyoungs_modulus = 50e6          # a soft polymer (Pa)\n\
               poisson_ratio = 0.45\nhamaker = 1e-20";
    assert!(water.contains(dmt), "the example's [sample] changed");
    for (sample, law) in [
        (
            "law = \"capillary\"\nyoungs_modulus = 50e6\npoisson_ratio = 0.45\n\
             meniscus_volume = 1e-25",
            "capillary",
        ),
        (
            "law = \"electrostatic\"\nyoungs_modulus = 50e6\npoisson_ratio = 0.45\n\
             hamaker = 1e-20\nbias_voltage = 1.0",
            "electrostatic",
        ),
    ] {
        let text = water.replace(dmt, sample);
        let e = Probe::parse(&text, "<test>").unwrap_err().to_string();
        assert!(e.contains(law) && e.contains("liquid [medium]"), "{e}");
        let air = text.replace("name = \"water\"", "name = \"air\"");
        Probe::parse(&air, "<test>").unwrap_or_else(|e| panic!("{law} in air: {e}"));
    }
}

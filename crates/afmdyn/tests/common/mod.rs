//! Test helpers shared by the integration tests: the closed-form forced response of a region
//! and the events of a run.

#[cfg(feature = "files")]
pub mod am_synthetic;
#[cfg(feature = "files")]
pub mod fm_check;
#[cfg(feature = "files")]
pub mod orbit_check;
#[cfg(feature = "files")]
pub mod orbit_params;

use afmdyn::galerkin::Region;
use afmdyn::integrate::{
    advance_dyn, build, Integrator, IntegratorKind, IntegratorOptions, SwitchEvent,
};
use afmdyn::request::analyses::OrbitRequest;
use afmdyn::{CantileverModel, ContactLaw, HybridSystem, SimError};
use nalgebra::{Complex, DMatrix, DVector};
use proptest::test_runner::{FailurePersistence, FileFailurePersistence};

/// Where a `proptest!` block keeps its failing cases: next to its source file, with the
/// extension `proptest-regressions` (`laws.rs` → `laws.proptest-regressions`). Proptest's
/// default would put them in `../proptest-regressions/laws.txt` now that `tests/` has a
/// `main.rs` (the default looks for a `lib.rs` or `main.rs` above the file, and fell back to
/// this place while the tests were binaries of their own).
pub fn regressions_beside_the_source() -> Option<Box<dyn FailurePersistence>> {
    Some(Box::new(FileFailurePersistence::WithSource(
        "proptest-regressions",
    )))
}

/// The model of the probe file's `text` (`origin` in its errors) with its SI units: what a
/// request runs on when given a probe.
pub fn resolved(text: &str, origin: &str) -> afmdyn::request::Resolved {
    let probe = afmdyn::probe::Probe::parse(text, origin).expect("probe");
    afmdyn::request::Resolved {
        params: probe.params,
        probe: Some(probe),
    }
}

/// The complex amplitude â of region `r`'s linear response a = Re(â e^{iΩτ}) to its harmonic
/// forcing: (K − Ω²M + iΩC) â = F_cos − i F_sin (eq. 10, shape `[N]`).
pub fn complex_response(model: &CantileverModel, r: Region) -> DVector<Complex<f64>> {
    let g = model.galerkin().region(r);
    let w = model.omega();
    let c = |m: &DMatrix<f64>| m.map(|v| Complex::new(v, 0.0));
    let dyn_stiff = c(&g.stiffness) - c(&g.mass) * Complex::new(w * w, 0.0)
        + c(&g.damping) * Complex::new(0.0, w);
    let rhs =
        g.forcing.cos.map(|v| Complex::new(v, 0.0)) - g.forcing.sin.map(|v| Complex::new(0.0, v));
    dyn_stiff.lu().solve(&rhs).unwrap()
}

/// Closed-form periodic forced response of region `r` from the second-order equations
/// M Ẍ + C Ẋ + K X = F(τ) (eq. 10): K X₀ = F_const and (K − Ω²M + iΩC) X̂ = F_cos − i F_sin.
/// Independent of the first-order solve inside the propagator. Returns z_p(τ) = (X, Ẋ) (and a
/// law's internal states at rest).
pub fn harmonic_response(model: &CantileverModel, r: Region, tau: f64) -> DVector<f64> {
    let g = model.galerkin().region(r);
    let w = model.omega();
    let xh = complex_response(model, r);
    let x0 = g.stiffness.clone().lu().solve(&g.forcing.constant).unwrap();
    let e = Complex::new((w * tau).cos(), (w * tau).sin());
    let n = model.modes();
    // a law's internal states at rest (an SLS sample out of reach stays relaxed)
    let mut z = DVector::zeros(model.dim());
    for j in 0..n {
        z[j] = x0[j] + (xh[j] * e).re;
        z[n + j] = (xh[j] * e * Complex::new(0.0, w)).re;
    }
    z
}

/// The events of `integ` up to `tau_end`.
pub fn events_until(integ: &mut dyn Integrator, tau_end: f64) -> Vec<SwitchEvent> {
    let mut ev = Vec::new();
    advance_dyn(integ, tau_end, &mut |_, s, _| {
        if let Some(e) = &s.event {
            ev.push(e.clone());
        }
        Ok(())
    })
    .unwrap();
    ev
}

/// An integrator against the adaptive DOP853 integrator at 1e-14 (the oracle), and DOP853 at
/// the integrator's own tolerance: see [`against_adaptive_oracle`].
#[allow(dead_code)] // `work` is read by no test at present
pub struct OracleComparison {
    /// Events of the run.
    pub events: usize,
    /// Largest difference of an event time from the oracle's.
    pub worst_event: f64,
    /// Largest difference of the final state from the oracle's.
    pub state: f64,
    /// The same for DOP853 at the integrator's tolerance.
    pub state_dop853: f64,
    /// Steps of the run ([`Integrator::work`]) and of DOP853 at the same tolerance.
    pub work: (u64, u64),
}

/// 30 drive periods of `m` from the steady state `afmdyn orbit` starts from, with `kind` at
/// `tol`, against the adaptive DOP853 integrator at 1e-14: the events matched one to one in
/// kind and regions (asserted; each on its guard to 1e-10), the largest differences of event
/// times and of the final state.
pub fn against_adaptive_oracle(
    m: &CantileverModel,
    kind: IntegratorKind,
    tol: f64,
) -> OracleComparison {
    let t_end = 30.0 * m.period();
    let (start, _) = OrbitRequest::default().start.guess(m).unwrap();
    let run = |kind, tol| {
        let opts = IntegratorOptions {
            kind,
            steps_per_period: 1,
            tolerance: tol,
            ..IntegratorOptions::default()
        };
        let mut it = build(m, opts, 0.0, &start).unwrap();
        let ev = events_until(it.as_mut(), t_end);
        assert_eq!(it.tau(), t_end, "{kind:?} lands on the end");
        (ev, it.state().clone(), it.work())
    };
    let (e1, z1, w1) = run(kind, tol);
    let (e2, z2, _) = run(IntegratorKind::Adaptive, 1e-14);
    let (_, z3, w3) = run(IntegratorKind::Adaptive, tol);
    assert_eq!(e1.len(), e2.len(), "{kind:?}: events");
    let mut worst_event = 0.0f64;
    for (x, y) in e1.iter().zip(&e2) {
        assert_eq!((x.kind, x.from, x.to), (y.kind, y.from, y.to), "{kind:?}");
        worst_event = worst_event.max((x.tau - y.tau).abs());
        let g = m.guard(x.from, x.tau, x.state.as_slice()).value;
        assert!(g.abs() < 1e-10, "{kind:?}: guard {g:e}");
    }
    OracleComparison {
        events: e1.len(),
        worst_event,
        state: (&z1 - &z2).amax(),
        state_dop853: (&z3 - &z2).amax(),
        work: (w1, w3),
    }
}

/// Whether `built` is [`SimError::Unsupported`] naming `integrator` (and `law`, when given): an
/// integrator refusing a law it does not integrate.
pub fn is_refusal<T>(built: &Result<T, SimError>, integrator: &str, law: Option<&str>) -> bool {
    matches!(built, Err(SimError::Unsupported { integrator: i, law: l, .. })
        if *i == integrator && law.is_none_or(|w| *l == w))
}

/// `law` without its long-range attraction (DMT with H̃ = 0; the other laws as they are): a
/// sample out of reach then exerts no force.
pub fn without_attraction(law: ContactLaw) -> ContactLaw {
    match law {
        ContactLaw::Dmt {
            intermolecular_distance,
            ..
        } => ContactLaw::Dmt {
            hamaker: 0.0,
            intermolecular_distance,
        },
        ContactLaw::Electrostatic {
            intermolecular_distance,
            tip_radius,
            ..
        } => ContactLaw::Electrostatic {
            hamaker: 0.0,
            intermolecular_distance,
            electrostatic: 0.0,
            tip_radius,
        },
        l => l,
    }
}

/// The impact law (restitution `r`) on `modes` modes at gap α5 = `gap` and drive Ω = `omega`.
pub fn impact_model(r: f64, modes: usize, gap: f64, omega: f64) -> afmdyn::CantileverModel {
    afmdyn::CantileverModel::new(&afmdyn::Params {
        modes,
        omega,
        alpha5: gap,
        contact_law: afmdyn::ContactLaw::Impact { restitution: r },
        ..afmdyn::Params::default()
    })
    .unwrap()
}

/// The options of integrator `kind` at tolerance `tol` (RK4 at 4 000 steps per period).
pub fn opts(kind: afmdyn::IntegratorKind, tol: f64) -> afmdyn::IntegratorOptions {
    afmdyn::IntegratorOptions {
        kind,
        steps_per_period: if matches!(kind, afmdyn::IntegratorKind::Rk4) {
            4000
        } else {
            1
        },
        tolerance: tol,
        ..Default::default()
    }
}

/// The eigenmode model with the first two modes of `beam` (a probe): each mode's stiffness at
/// the tip k̃_j (Melcher, Hu & Raman 2007, [`afmdyn::eigen::mode_at_tip`]), natural frequency f_j
/// and quality factor Q_j = 1/(2ζ_j) as the beam gives them, over the sections `tail` (tip,
/// sample, drive).
pub fn two_modes_of(beam: &afmdyn::probe::Probe, tail: &str) -> afmdyn::probe::Probe {
    let (free, _) = afmdyn::eigen::spectrum(&beam.params).unwrap();
    let g = afmdyn::galerkin::Galerkin::new(&beam.params).unwrap();
    let s = &beam.scales;
    let (mut k, mut f, mut q) = (Vec::new(), Vec::new(), Vec::new());
    for j in 0..2 {
        let (w, _, kt) = afmdyn::eigen::mode_at_tip(g.region(Region::Free), g.tip(), j);
        k.push(format!("{:e}", kt * s.force_n / s.length_m));
        f.push(format!("{:e}", s.frequency_hz(w)));
        let zeta = free
            .eigenvalues
            .iter()
            .filter(|e| e.im > 0.0)
            .nth(j)
            .unwrap()
            .zeta;
        q.push(format!("{:e}", 0.5 / zeta));
    }
    afmdyn::probe::Probe::parse(
        &format!(
            "model = \"eigenmodes\"\n[cantilever]\nspring_constant = [{}]\n\
             resonance_frequency = [{}]\nquality_factor = [{}]\n{tail}",
            k.join(", "),
            f.join(", "),
            q.join(", ")
        ),
        "test",
    )
    .unwrap()
}

/// The tip and sample of the eigenmode-model checks: a 10 nm tip over polystyrene (DMT,
/// E = 4 GPa, H = 6.6e-20 J), z_c = 8 nm.
pub const TIP_OVER_POLYSTYRENE: &str = "[tip]\nradius = 10e-9\n[sample]\nlaw = \"dmt\"\n\
     youngs_modulus = 4e9\npoisson_ratio = 0.33\nhamaker = 6.6e-20\nz_c = 8e-9\n";

/// The bimodal probe of the checks: the eigenmode model of a 40 N/m lever (as
/// `examples/probe-bimodal.toml`: k = [40, 1571] N/m, f₁ = 300 kHz) with mode 2 at `f2_mode`
/// (Hz) and quality factors `q` ("Q1, Q2"), over [`TIP_OVER_POLYSTYRENE`], driven with
/// free amplitudes [10 nm, 1 nm] at [300 kHz, `f2`].
pub fn bimodal_lever(f2_mode: &str, q: &str, f2: &str) -> String {
    format!(
        "model = \"eigenmodes\"\n[cantilever]\nspring_constant = [40.0, 1571.0]\n\
         resonance_frequency = [300e3, {f2_mode}]\nquality_factor = [{q}]\n\
         {TIP_OVER_POLYSTYRENE}[drive]\nfree_amplitude = [10e-9, 1e-9]\n\
         frequency = [300e3, {f2}]\n"
    )
}

/// Gauss–Legendre nodes and weights on [−1, 1] (Newton on P_n from Chebyshev guesses).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 0.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// A hysteretic law's tap (JKR's neck, the capillary meniscus) on `m`'s stable period-1 orbit,
/// found from 300 periods of transient by shooting, losing `e` per tap with no viscous damping:
/// the observables' E_dis is `e` (1e-8), and 5 recorded periods show 10 switchings — the
/// contact formed at V_T = 0 and left at V_T = [`CantileverModel::release_distance`] (1e-10)
/// — with `e` booked per period and the energy balance closed to 1e-9 of the energy through a
/// period. Returns the orbit's state at τ = 0.
pub fn hysteretic_tap(m: &CantileverModel, e: f64) -> DVector<f64> {
    use afmdyn::analysis::observables::{observe, ObservableOptions};
    use afmdyn::analysis::shooting::{shoot, ShootingOptions};
    use afmdyn::trajectory::{record, RecordSpec};
    let spec = |transient: f64, periods: f64, energy: bool| RecordSpec {
        transient_periods: transient,
        record_tau: periods * m.period(),
        samples_per_period: if energy { 16 } else { 0 },
        energy,
        body_contact: false,
    };
    let mut it = build(m, IntegratorOptions::default(), 0.0, &m.rest()).unwrap();
    let warm = afmdyn::trajectory::record(it.as_mut(), &spec(300.0, 0.0, false)).unwrap();
    let mut fresh = build(m, IntegratorOptions::default(), 0.0, &m.rest()).unwrap();
    let map = &mut afmdyn::maps::StroboscopicMap::new(fresh.as_mut(), 1);
    let o = shoot(map, &warm.final_state, &ShootingOptions::default()).unwrap();
    assert!(o.stable);
    let mut it = build(m, IntegratorOptions::default(), 0.0, &o.state).unwrap();
    let obs = observe(it.as_mut(), &ObservableOptions::default()).unwrap();
    let got = obs.energy_dissipated;
    assert!((got / e - 1.0).abs() < 1e-8, "E_dis {got} vs {e}");
    let mut it = build(m, IntegratorOptions::default(), 0.0, &o.state).unwrap();
    let tr = record(it.as_mut(), &spec(0.0, 5.0, true)).unwrap();
    assert_eq!(tr.events.len(), 10);
    for ev in &tr.events {
        assert_eq!(ev.kind, afmdyn::EventKind::Switching);
        let v = m.v_t(ev.tau, &ev.state);
        let want = if ev.to == Region::Contact {
            0.0
        } else {
            m.release_distance()
        };
        assert!((v - want).abs() < 1e-10, "{:?}: V_T {v} vs {want}", ev.to);
    }
    for b in &tr.energy {
        let scale = b.base_work.abs().max(e);
        let res = b.residual();
        assert!(res.abs() < 1e-9 * scale, "residual {res} of {scale}");
        let booked = b.contact_dissipation;
        assert!((booked / e - 1.0).abs() < 1e-7, "{booked} vs {e}");
    }
    o.state
}

/// The laws with groups, at the library's defaults ([`afmdyn::contact`]'s `*_DEFAULT*`): the
/// law sets of the conformance and law suites.
pub mod laws {
    use afmdyn::contact::*;
    use afmdyn::ContactLaw;

    /// DMT (H̃ = 1e-5, ã₀ = 0.01).
    pub const DMT: ContactLaw = ContactLaw::Dmt {
        hamaker: DMT_DEFAULT_HAMAKER,
        intermolecular_distance: DMT_DEFAULT_A0,
    };
    /// The electrostatic law (DMT's groups, Ẽ = 1e-3, R̃ = 1).
    pub const ES: ContactLaw = ContactLaw::Electrostatic {
        hamaker: DMT_DEFAULT_HAMAKER,
        intermolecular_distance: DMT_DEFAULT_A0,
        electrostatic: ELECTROSTATIC_DEFAULT,
        tip_radius: ELECTROSTATIC_DEFAULT_RADIUS,
    };
    /// JKR (P̃ = 0.05): a hysteretic region (the neck, left at V_T = |δ_b|).
    pub const JKR: ContactLaw = ContactLaw::Jkr {
        adhesion: JKR_DEFAULT_ADHESION,
    };
    /// The capillary meniscus (F̃_cap = 0.1, h̃ = 0.01, D̃_r = 0.05): hysteretic too (left at
    /// V_T = D̃_r), with a kink in the force inside its region (at V_T = 0).
    pub const CAP: ContactLaw = ContactLaw::Capillary {
        capillary: CAPILLARY_DEFAULT_FORCE,
        meniscus: CAPILLARY_DEFAULT_MENISCUS,
        rupture: CAPILLARY_DEFAULT_RUPTURE,
    };
    /// The standard linear solid (κ = 20): one internal state (the dashpot's extension u, the
    /// state's last entry), a guard over the recovering surface.
    pub const SLS: ContactLaw = ContactLaw::Sls {
        maxwell_stiffness: SLS_DEFAULT_MAXWELL,
    };
}

/// A region's vector field ż = f(contact, τ, z).
pub type RegionField<'a> = &'a dyn Fn(bool, f64, &DVector<f64>) -> DVector<f64>;

/// An independent integrator of a two-region switched system, for the tests: fixed-step RK4
/// of `rhs(contact, τ, z)` from z(0) = `z0` to `t1` with steps of `h`; the region starts as
/// `below(0, z0)` (in contact when the switching function is negative) and a change of sign of
/// the switching function inside a step, `below(τ, z) != contact`, is located by bisection on
/// the step length (60 halvings) and the region switched there.
pub fn rk4_switched_flow(
    rhs: RegionField<'_>,
    below: &dyn Fn(f64, &DVector<f64>) -> bool,
    z0: &DVector<f64>,
    t1: f64,
    h: f64,
) -> DVector<f64> {
    let rk4 = |contact: bool, tau: f64, z: &DVector<f64>, h: f64| {
        let k1 = rhs(contact, tau, z);
        let k2 = rhs(contact, tau + h / 2.0, &(z + &k1 * (h / 2.0)));
        let k3 = rhs(contact, tau + h / 2.0, &(z + &k2 * (h / 2.0)));
        let k4 = rhs(contact, tau + h, &(z + &k3 * h));
        z + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0)
    };
    let (mut tau, mut z) = (0.0, z0.clone());
    let mut contact = below(0.0, z0);
    while tau < t1 - 1e-14 {
        let step = h.min(t1 - tau);
        let inside = |zz: &DVector<f64>, t: f64| below(t, zz) == contact;
        let zb = rk4(contact, tau, &z, step);
        if inside(&zb, tau + step) {
            z = zb;
            tau += step;
            continue;
        }
        let (mut lo, mut hi) = (0.0, step);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if inside(&rk4(contact, tau, &z, mid), tau + mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        z = rk4(contact, tau, &z, hi);
        tau += hi;
        contact = !contact;
    }
    z
}

/// The free region of a model written again from its Galerkin matrices (eqs. 11–14), for the
/// tests' independent integrators: M ä + C ȧ + K a = F_s sin Ωτ + F_c cos Ωτ + φ F_tip.
pub struct FreeBeam {
    minv: DMatrix<f64>,
    c: DMatrix<f64>,
    k: DMatrix<f64>,
    fs: DVector<f64>,
    fc: DVector<f64>,
    /// φ(1), shape `[N]`.
    pub tip: DVector<f64>,
    /// The parameters.
    pub p: afmdyn::Params,
}

impl FreeBeam {
    /// The matrices of `model`'s free region.
    pub fn of(model: &CantileverModel) -> Self {
        let g = model.galerkin().region(Region::Free);
        FreeBeam {
            minv: g.mass.clone().try_inverse().unwrap(),
            c: g.damping.clone(),
            k: g.stiffness.clone(),
            fs: g.forcing.sin.clone(),
            fc: g.forcing.cos.clone(),
            tip: model.tip().clone(),
            p: *model.params(),
        }
    }

    /// (V_T, dV_T/dτ) at (τ, z) (eq. 8 for the beam: φᵀa + α2 sin Ωτ + α5).
    pub fn v_t(&self, tau: f64, z: &DVector<f64>) -> (f64, f64) {
        let n = self.p.modes;
        let (s, c) = (self.p.omega * tau).sin_cos();
        (
            self.tip.dot(&z.rows(0, n)) + self.p.alpha2 * s + self.p.alpha5,
            self.tip.dot(&z.rows(n, n)) + self.p.alpha2 * self.p.omega * c,
        )
    }

    /// ż = (ȧ, M⁻¹(F(τ) − Cȧ − Ka + φ F_tip)) of the first 2N entries of z, in a vector of
    /// `dim` entries (the rest 0, for a law's internal states to fill).
    pub fn rhs(&self, tau: f64, z: &DVector<f64>, tip_force: f64, dim: usize) -> DVector<f64> {
        let n = self.p.modes;
        let (s, c) = (self.p.omega * tau).sin_cos();
        let (a, ad) = (z.rows(0, n), z.rows(n, n));
        let f = &self.fs * s + &self.fc * c - &self.c * ad - &self.k * a + &self.tip * tip_force;
        let mut out = DVector::zeros(dim);
        out.rows_mut(0, n).copy_from(&ad);
        out.rows_mut(n, n).copy_from(&(&self.minv * f));
        out
    }
}

/// The model of examples/probe-fit-hertz.toml (the force-curve fits' probe: k = 0.05 N/m,
/// R = 5 µm, a Hertz sample of ν = 0.5).
pub fn fit_hertz_probe() -> afmdyn::request::Resolved {
    let text = include_str!("../../../../examples/probe-fit-hertz.toml");
    let p = afmdyn::probe::Probe::parse(text, "probe-fit-hertz.toml").expect("probe");
    afmdyn::request::Resolved {
        params: p.params,
        probe: Some(p),
    }
}

/// The generated section of the doc `doc` (a path from the repository's root) between the
/// markers `begin` and `end` equals `body`, or (`AFMDYN_WRITE_SCHEMA=1`) is rewritten to it;
/// `module` names the test module that regenerates it (`laws_table`).
pub fn generated_section(doc: &str, begin: &str, end: &str, body: &str, module: &str) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(doc);
    let text = std::fs::read_to_string(&path).unwrap();
    let (head, rest) = (text.split_once(begin)).unwrap_or_else(|| panic!("{doc} lacks {begin}"));
    let (_, tail) = (rest.split_once(end)).unwrap_or_else(|| panic!("{doc} lacks {end}"));
    let want = format!("{head}{begin}\n{body}{end}{tail}");
    if std::env::var_os("AFMDYN_WRITE_SCHEMA").is_some_and(|v| v == "1") {
        std::fs::write(&path, want).unwrap();
    } else {
        assert!(
            text == want,
            "{doc}'s generated section differs from the library; regenerate with \
             AFMDYN_WRITE_SCHEMA=1 cargo test -p afmdyn --lib integration::{module}::"
        );
    }
}

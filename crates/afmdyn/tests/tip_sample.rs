//! The integrators and the analyses are written against [`TipSampleSystem`], not the
//! cantilever: here they run on a second system, a harmonically forced, damped oscillator over
//! a linear-spring sample (a soft-impact oscillator, e.g. di Bernardo et al., *Piecewise-smooth
//! Dynamical Systems*, Springer 2008, §1.2.3), in one modal coordinate (N = 1, z = (a, ȧ)):
//!
//! ä + 2ζȧ + a = F sin Ωτ                 while V_T = a + d > 0 (free),
//! ä + 2ζȧ + a + k_c (a + d) = F sin Ωτ    while V_T ≤ 0 (contact).
//!
//! The references are closed forms: the harmonic response and the Floquet multipliers
//! e^{λT}, λ = −ζ ± i√(1−ζ²), of the linear oscillator away from the sample; and, on an orbit
//! that touches it, Liouville's formula det M = e^{−2ζT} (the trace of the Jacobian is −2ζ in
//! both regions, and the vector field is continuous across V_T = 0, so every saltation matrix
//! has determinant 1), which the Lyapunov exponents obey as λ₁ + λ₂ = −2ζ.

use afmdyn::analysis::lyapunov::{lyapunov_spectrum_with, LyapunovOptions};
use afmdyn::analysis::shooting::{shoot, ShootingOptions};
use afmdyn::analysis::steady::{steady_state, Motion, SteadyOptions};
use afmdyn::integrate::adaptive::Adaptive;
use afmdyn::integrate::rk4::Rk4;
use afmdyn::integrate::Integrator;
use afmdyn::maps::StroboscopicMap;
use afmdyn::system::{Guard, Jump};
use afmdyn::tip_sample::require_cantilever;
use afmdyn::{HybridSystem, Region, SimError, TipSampleSystem};
use nalgebra::{DMatrix, DVector};
use std::f64::consts::PI;

/// The soft-impact oscillator of the module docs.
#[derive(Debug, Clone)]
struct SoftImpact {
    zeta: f64,
    k_c: f64,
    force: f64,
    omega: f64,
    gap: f64,
    tip: DVector<f64>,
}

impl SoftImpact {
    fn new(gap: f64) -> Self {
        SoftImpact {
            zeta: 0.05,
            k_c: 20.0,
            force: 0.3,
            omega: 0.8,
            gap,
            tip: DVector::from_element(1, 1.0),
        }
    }
    fn stiffness(&self, mode: Region) -> f64 {
        match mode {
            Region::Free => 1.0,
            Region::Contact => 1.0 + self.k_c,
        }
    }
    /// Harmonic response a_p(τ) = A sin(Ωτ − φ) of the free oscillator at τ = 0, (a, ȧ).
    fn free_response_at_zero(&self) -> [f64; 2] {
        let (om, z) = (self.omega, self.zeta);
        let amp = self.force / ((1.0 - om * om).powi(2) + (2.0 * z * om).powi(2)).sqrt();
        let phi = (2.0 * z * om).atan2(1.0 - om * om);
        [-amp * phi.sin(), amp * om * phi.cos()]
    }
}

impl HybridSystem for SoftImpact {
    fn dim(&self) -> usize {
        2
    }
    fn period(&self) -> f64 {
        2.0 * PI / self.omega
    }
    fn mode_at(&self, tau: f64, z: &[f64]) -> Region {
        let _ = tau;
        let v = z[0] + self.gap;
        if v < 0.0 || (v == 0.0 && z[1] <= 0.0) {
            Region::Contact
        } else {
            Region::Free
        }
    }
    fn rhs(&self, mode: Region, tau: f64, z: &[f64], dz: &mut [f64]) {
        let spring = match mode {
            Region::Free => z[0],
            Region::Contact => z[0] + self.k_c * (z[0] + self.gap),
        };
        dz[0] = z[1];
        dz[1] = -spring - 2.0 * self.zeta * z[1] + self.force * (self.omega * tau).sin();
    }
    fn jacobian(&self, mode: Region, tau: f64, z: &[f64], jac: &mut DMatrix<f64>) {
        let _ = (tau, z);
        *jac = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -self.stiffness(mode), -2.0 * self.zeta]);
    }
    fn guard(&self, mode: Region, tau: f64, z: &[f64]) -> Guard {
        let _ = tau;
        let s = mode.guard_sign();
        Guard {
            value: s * (z[0] + self.gap),
            grad: DVector::from_row_slice(&[s, 0.0]),
            d_tau: 0.0,
        }
    }
    fn jump(&self, from: Region, tau: f64, z: &[f64]) -> Jump {
        let _ = tau;
        Jump::switching(from.other(), z)
    }
    fn is_affine(&self) -> bool {
        true
    }
}

impl TipSampleSystem for SoftImpact {
    fn omega(&self) -> f64 {
        self.omega
    }
    fn tip(&self) -> &DVector<f64> {
        &self.tip
    }
    fn v_t_from_tip(&self, tau: f64, w: [f64; 3]) -> [f64; 3] {
        let _ = tau;
        [w[0] + self.gap, w[1], w[2]]
    }
    fn tip_values(&self, tau: f64, z: &DVector<f64>) -> [f64; 4] {
        let [v, vd, _] = self.v_t_from_tip(tau, [z[0], z[1], 0.0]);
        [z[0], z[1], v, vd]
    }
    fn law_name(&self) -> &'static str {
        "soft impact"
    }
    /// |Re λ| = ζ of λ = −ζ ± i√(1−ζ²); none for the undamped oscillator.
    fn free_decay_rate(&self) -> Option<f64> {
        (self.zeta > 0.0).then_some(self.zeta)
    }
}

/// The adaptive DOP853 and the located-event RK4 of the system, both at rest at τ = 0.
fn integrators(sys: &SoftImpact) -> Vec<Box<dyn Integrator>> {
    let rest = DVector::zeros(2);
    let mut out: Vec<Box<dyn Integrator>> = vec![
        Box::new(Adaptive::new(sys, 1e-12)),
        Box::new(Rk4::new(sys, 2000, true)),
    ];
    for it in &mut out {
        it.reset(0.0, &rest).unwrap();
    }
    out
}

#[test]
fn away_from_the_sample_the_steady_state_and_multipliers_are_the_linear_oscillators() {
    let sys = SoftImpact::new(10.0);
    let [a0, v0] = sys.free_response_at_zero();
    let t = sys.period();
    let decay = (-sys.zeta * t).exp();
    let arg = (1.0 - sys.zeta * sys.zeta).sqrt() * t;
    for mut it in integrators(&sys) {
        let name = it.name();
        let ss = steady_state(it.as_mut(), &SteadyOptions::default()).unwrap();
        assert_eq!(ss.motion, Motion::Periodic { period: 1 }, "{name}");
        assert_eq!(ss.stats.contact_fraction, 0.0, "{name}");
        let z = ss.end_state();
        assert!(
            (z[0] - a0).abs() < 1e-7 && (z[1] - v0).abs() < 1e-7,
            "{name}: {z} vs ({a0}, {v0})"
        );
        let w = ss.poincare[0].w_tip;
        assert!((w - a0).abs() < 1e-7, "{name}: W = {w}");
        if name == "rk4" {
            // RK4 has no step Jacobians: refused, not guessed
            let map = &mut StroboscopicMap::new(it.as_mut(), 1);
            let err = shoot(map, z, &ShootingOptions::default()).unwrap_err();
            assert!(matches!(err, SimError::Unsupported { .. }), "{err}");
            continue;
        }
        let map = &mut StroboscopicMap::new(it.as_mut(), 1);
        let orbit = shoot(map, z, &ShootingOptions::default()).unwrap();
        assert!(orbit.stable && orbit.switchings == 0);
        for mu in &orbit.multipliers {
            assert!(
                (mu.norm() - decay).abs() < 1e-9,
                "|μ| = {} vs {decay}",
                mu.norm()
            );
            let want = arg.sin().abs() * decay;
            assert!(
                (mu.im.abs() - want).abs() < 1e-9,
                "Im μ = {} vs {want}",
                mu.im
            );
        }
    }
}

#[test]
fn an_orbit_that_touches_the_sample_keeps_liouvilles_volume_law() {
    let sys = SoftImpact::new(0.3);
    let t = sys.period();
    let mut ends = Vec::new();
    for mut it in integrators(&sys) {
        let name = it.name();
        let ss = steady_state(it.as_mut(), &SteadyOptions::default()).unwrap();
        assert_eq!(ss.period(), Some(1), "{name}");
        assert!(ss.stats.contact_fraction > 0.05, "{name}: {:?}", ss.stats);
        assert!(!ss.stats.body_contact, "{name}: no body to touch");
        ends.push(ss.end_state().clone());
        if name == "rk4" {
            continue;
        }
        let map = &mut StroboscopicMap::new(it.as_mut(), 1);
        let orbit = shoot(map, ss.end_state(), &ShootingOptions::default()).unwrap();
        assert_eq!(orbit.switchings, 2);
        let det = orbit.monodromy.determinant();
        let want = (-2.0 * sys.zeta * t).exp();
        assert!((det / want - 1.0).abs() < 1e-8, "det M = {det} vs {want}");
        let opts = LyapunovOptions {
            transient_periods: 0,
            periods: 200,
            blocks: 4,
            ..LyapunovOptions::default()
        };
        it.reset(0.0, &orbit.state).unwrap();
        let l = lyapunov_spectrum_with(it.as_mut(), &opts, &Default::default()).unwrap();
        let sum: f64 = l.exponents.iter().sum();
        assert!((sum + 2.0 * sys.zeta).abs() < 1e-9, "λ1 + λ2 = {sum}");
        assert!(l.exponents[0] < 0.0);
    }
    // the two integrators reach the same orbit (RK4 at 2000 steps per period: error ~h⁴)
    assert!(
        (&ends[0] - &ends[1]).norm() < 1e-6,
        "{} vs {}",
        ends[0],
        ends[1]
    );
}

/// The stroboscopic map is a layer over any system: on the oscillator's touching orbit, P² is
/// P applied twice, its monodromy matrix is the product of the two period-1 matrices (chain
/// rule, saltation included) with Liouville's determinant e^{−2ζ·2T}, the map without the
/// Jacobian gives the same image, and the grazing distance alone equals the watched map's.
/// (The exact propagator's are equal bit for bit: `tests/stability.rs`.)
#[test]
fn the_stroboscopic_map_composes_on_another_system() {
    use afmdyn::maps::StroboscopicMap;
    let sys = SoftImpact::new(0.3);
    let mut it = Adaptive::new(&sys, 1e-12);
    it.reset(0.0, &DVector::zeros(2)).unwrap();
    let ss = steady_state(&mut it, &SteadyOptions::default()).unwrap();
    // a start off the orbit, so that the two iterates differ
    let z = ss.end_state() + DVector::from_vec(vec![0.05, -0.02]);
    let one = StroboscopicMap::new(&mut it, 1).apply(&z).unwrap();
    let again = StroboscopicMap::new(&mut it, 1).apply(&one.state).unwrap();
    let two = StroboscopicMap::new(&mut it, 2).apply(&z).unwrap();
    assert!(one.contacts >= 1 && two.contacts == one.contacts + again.contacts);
    assert!((&two.state - &again.state).amax() < 1e-9, "P² vs P∘P");
    let chain = &again.jacobian * &one.jacobian;
    assert!(
        (&two.jacobian - &chain).amax() < 1e-7,
        "M₂ vs M₁(P z) M₁(z)"
    );
    let want = (-2.0 * sys.zeta * 2.0 * sys.period()).exp();
    let det = two.jacobian.determinant();
    assert!((det / want - 1.0).abs() < 1e-8, "det M₂ = {det} vs {want}");
    let image = StroboscopicMap::new(&mut it, 2).image(&z).unwrap();
    assert!((&image - &two.state).amax() < 1e-9);
    // the adaptive integrator starts each flow with its last step size (a warm start), so a
    // replay agrees to round-off, not bit for bit
    let grazing = StroboscopicMap::new(&mut it, 2)
        .grazing_distance(&z)
        .unwrap();
    assert!((grazing - two.grazing_distance).abs() < 1e-12, "{grazing}");
    let unwatched = StroboscopicMap::new(&mut it, 2)
        .watch_grazing(false)
        .apply(&z)
        .unwrap();
    assert!(unwatched.grazing_distance.is_nan());
    assert!((&unwatched.state - &two.state).amax() < 1e-12);
}

/// The transient caps of the steady-state searches come from the system's free decay rate,
/// whatever the system: ln(1/tol)/(ζT) drive periods for the oscillator (λ = −ζ ± i√(1−ζ²)),
/// and the floor for the undamped one, which has none.
#[test]
fn the_transient_cap_follows_any_systems_decay_rate() {
    use afmdyn::analysis::steady::{decay_periods, default_transient_cap, MIN_TRANSIENT_PERIODS};
    let sys = SoftImpact::new(0.3);
    let closed = (1e8f64).ln() / (sys.zeta * 2.0 * PI / sys.omega);
    let decay = decay_periods(&sys, 1e-8).unwrap();
    assert!(
        (decay - closed).abs() <= 1e-12 * closed,
        "{decay} vs {closed}"
    );
    let undamped = SoftImpact {
        zeta: 0.0,
        ..SoftImpact::new(0.3)
    };
    assert_eq!(decay_periods(&undamped, 1e-8), None);
    assert_eq!(
        default_transient_cap(&undamped, 1e-8),
        MIN_TRANSIENT_PERIODS
    );
    // the body check is the cantilever's: the oscillator has no body
    assert!(sys.body_contact_check(32).is_none());
}

#[test]
fn analyses_that_need_the_cantilever_refuse_another_system() {
    let sys = SoftImpact::new(0.3);
    let mut it = Adaptive::new(&sys, 1e-10);
    it.reset(0.0, &DVector::zeros(2)).unwrap();
    let err = require_cantilever(it.system(), "the AFM observables").unwrap_err();
    assert_eq!(
        err.to_string(),
        "the AFM observables needs the cantilever model (its Galerkin matrices and mode shapes); this system is not one"
    );
    let spec = afmdyn::trajectory::RecordSpec {
        transient_periods: 0.0,
        record_tau: 1.0,
        samples_per_period: 10,
        energy: false,
        body_contact: false,
    };
    let err = afmdyn::trajectory::record(&mut it, &spec).unwrap_err();
    assert!(matches!(err, SimError::NotCantilever { .. }), "{err}");
}

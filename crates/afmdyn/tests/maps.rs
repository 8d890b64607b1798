//! Conformance of [`DiscreteMap`] implementations: one suite of the map-only analyses (Newton
//! shooting and Floquet multipliers, section points, the minimal period) run on two maps,
//! each against its closed form —
//!
//! - an affine map z ↦ A z + b implemented here: fixed point (I − A)⁻¹ b, multipliers eig(A),
//!   stable exactly when the spectral radius is below 1;
//! - [`StroboscopicMap`] on the paper's piecewise-linear model with the sample out of reach:
//!   the period-1 orbit is the harmonic forced response of eq. 10
//!   (`common::harmonic_response`) and its multipliers are e^{λT}, λ the eigenvalues of the
//!   free region's system matrix —
//!
//! and the trait's view of the stroboscopic map is checked to be its inherent methods' numbers
//! bit for bit (Pᵏ of a period-n map is one flow over k·n periods).

use afmdyn::analysis::settle::minimal_period;
use afmdyn::analysis::shooting::{
    map_section_points, shoot, Guess, ShootingOptions, ShootingStrategy,
};
use afmdyn::galerkin::Region;
use afmdyn::integrate::{build, IntegratorOptions};
use afmdyn::maps::flow::FlowMap;
use afmdyn::maps::{DiscreteMap, StroboscopicMap};
use afmdyn::{CantileverModel, Params, SimError};
use nalgebra::{Complex, DMatrix, DVector};

use super::common;
use common::harmonic_response;

/// z ↦ A z + b: Pⁿ(z) by n images, ∂Pⁿ/∂z = Aⁿ, no events.
struct Affine {
    a: DMatrix<f64>,
    b: DVector<f64>,
    /// Images computed (to check that the analyses call the map, not something else).
    calls: usize,
}

impl Affine {
    fn new(a: DMatrix<f64>, b: DVector<f64>) -> Self {
        Affine { a, b, calls: 0 }
    }

    fn fixed_point(&self) -> DVector<f64> {
        let d = self.b.len();
        (DMatrix::identity(d, d) - &self.a)
            .lu()
            .solve(&self.b)
            .unwrap()
    }

    fn eigenvalues(&self) -> Vec<Complex<f64>> {
        let mut mu: Vec<Complex<f64>> = self.a.complex_eigenvalues().iter().copied().collect();
        mu.sort_by(|x, y| y.norm().total_cmp(&x.norm()));
        mu
    }
}

impl DiscreteMap for Affine {
    fn dim(&self) -> usize {
        self.b.len()
    }

    fn periods(&self) -> usize {
        1
    }

    fn duration(&self) -> f64 {
        1.0
    }

    fn iterate(&mut self, z: &DVector<f64>, n: usize) -> Result<DVector<f64>, SimError> {
        let mut x = z.clone();
        for _ in 0..n {
            self.calls += 1;
            x = &self.a * x + &self.b;
        }
        Ok(x)
    }

    fn linearise(
        &mut self,
        z: &DVector<f64>,
        n: usize,
        _grazing: bool,
    ) -> Result<FlowMap, SimError> {
        let d = self.dim();
        let mut jacobian = DMatrix::identity(d, d);
        for _ in 0..n {
            jacobian = &self.a * jacobian;
        }
        Ok(FlowMap {
            state: self.iterate(z, n)?,
            log_volume: jacobian.determinant().abs().ln(),
            jacobian,
            switchings: 0,
            contacts: 0,
            grazing_distance: f64::INFINITY,
            contact_time: 0.0,
            param_derivative: None,
        })
    }
}

/// A 3×3 A with a complex pair of modulus `r` and a real eigenvalue `real`, in a skewed basis.
fn affine(r: f64, real: f64) -> Affine {
    let (c, s) = (0.6f64, 0.8f64);
    let block = DMatrix::from_row_slice(
        3,
        3,
        &[r * c, -r * s, 0.0, r * s, r * c, 0.0, 0.0, 0.0, real],
    );
    let basis = DMatrix::from_row_slice(3, 3, &[1.0, 0.3, -0.2, 0.1, 1.0, 0.4, 0.5, -0.1, 1.0]);
    let a = &basis * block * basis.clone().try_inverse().unwrap();
    Affine::new(a, DVector::from_vec(vec![0.7, -1.2, 0.4]))
}

fn assert_multipliers(got: &[Complex<f64>], want: &[Complex<f64>], tol: f64) {
    assert_eq!(got.len(), want.len());
    for w in want {
        let best = got
            .iter()
            .map(|m| (m - w).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(best < tol, "{w} not among {got:?}");
    }
}

/// Newton on the affine map: one step from any guess (the map is its own linearisation), the
/// closed-form fixed point and multipliers, stability from the spectral radius — unstable
/// orbits (a real eigenvalue 1.7, a complex pair outside) converge all the same.
#[test]
fn shooting_finds_the_fixed_point_and_multipliers_of_an_affine_map() {
    let opts = ShootingOptions::default();
    for (r, real, stable) in [(0.5, -0.3, true), (0.9, 1.7, false), (1.2, 0.2, false)] {
        let mut m = affine(r, real);
        let want = m.fixed_point();
        let mu = m.eigenvalues();
        let guess = DVector::from_vec(vec![3.0, -2.0, 5.0]);
        let o = shoot(&mut m, &guess, &opts).unwrap();
        assert!(
            (&o.state - &want).amax() < 1e-12 * (1.0 + want.amax()),
            "r = {r}"
        );
        assert_multipliers(&o.multipliers, &mu, 1e-12);
        assert_eq!(o.stable, stable, "r = {r}, {real}");
        assert_eq!(o.period, 1);
        assert_eq!(o.section, vec![o.state.clone()]);
        assert_eq!(o.switchings, 0);
        assert!(!o.grazing);
        assert!(o.residuals.len() <= 3, "{:?}", o.residuals);
        assert!(m.calls > 0);
        // the other solvers reach the same point (Broyden from a 2 % wrong monodromy estimate,
        // as the previous orbit's along a sweep)
        let m0 = &m.a * 1.02;
        let dmap: &mut dyn DiscreteMap = &mut m;
        let by = |strategy| ShootingOptions { strategy, ..opts };
        let g = shoot(dmap, &guess, &by(ShootingStrategy::Globalised)).unwrap();
        let u = shoot(dmap, &guess, &by(ShootingStrategy::Undamped)).unwrap();
        let estimated = Guess::Estimated {
            state: &guess,
            monodromy: &m0,
        };
        let b = shoot(dmap, estimated, &by(ShootingStrategy::Broyden)).unwrap();
        for z in [&g.state, &u.state, &b.state] {
            assert!((z - &want).amax() < 1e-9 * (1.0 + want.amax()), "r = {r}");
        }
        assert_multipliers(&u.multipliers, &mu, 1e-12);
    }
}

/// The strategy of Broyden's updates from M ≈ 0 on the affine map: where A contracts (spectral
/// radius 0.5) the updates reach the closed-form fixed point within Gay's bound of 2d steps
/// (d = 3; Gay, SIAM J. Numer. Anal. 16 (1979) 623) and one variational map gives the
/// multipliers, the eigenvalues of A; where A expands (a real eigenvalue 1.7, a complex pair of
/// modulus 1.2) the first step — the map's own iterate — raises the residual and the solve is
/// Newton's from the guess, bit for bit; at period 2, and with the Newton strategy, it is
/// Newton's too.
#[test]
fn broyden_from_zero_reaches_the_affine_fixed_point_or_falls_back_on_newton() {
    let unwatched = ShootingOptions {
        watch_grazing: false,
        ..ShootingOptions::default()
    };
    let from_zero = ShootingOptions {
        strategy: ShootingStrategy::BroydenFromZero,
        ..unwatched
    };
    let guess = DVector::from_vec(vec![3.0, -2.0, 5.0]);
    let mut m = affine(0.5, -0.3);
    let want = m.fixed_point();
    let mu = m.eigenvalues();
    let b = shoot(&mut m, &guess, &from_zero).unwrap();
    let newton = shoot(&mut m, &guess, &unwatched).unwrap();
    assert!((&b.state - &want).amax() < 1e-10 * (1.0 + want.amax()));
    assert_multipliers(&b.multipliers, &mu, 1e-12);
    assert!(b.stable);
    assert_eq!((b.period, b.section.clone()), (1, vec![b.state.clone()]));
    assert!(b.grazing_distance.is_nan() && !b.grazing);
    // Broyden's iterates (up to 2d + 1 residuals and the variational map's), not Newton's two
    assert_eq!(newton.residuals.len(), 2);
    assert!(
        (3..=2 * 3 + 2).contains(&b.residuals.len()),
        "{:?}",
        b.residuals
    );
    for (r, real) in [(0.9, 1.7), (1.2, 0.2)] {
        let mut m = affine(r, real);
        let b = shoot(&mut m, &guess, &from_zero).unwrap();
        let newton = shoot(&mut m, &guess, &unwatched).unwrap();
        assert!(!b.stable);
        assert_eq!(b.state, newton.state, "r = {r}, {real}");
        assert_eq!(b.residuals, newton.residuals, "r = {r}, {real}");
    }
    for (n, strategy) in [
        (2, ShootingStrategy::BroydenFromZero),
        (1, ShootingStrategy::Newton),
    ] {
        let mut m = affine(0.5, -0.3);
        let period = unwatched.with_period(n);
        let o = shoot(&mut m, &guess, &ShootingOptions { strategy, ..period }).unwrap();
        let newton = shoot(&mut m, &guess, &period).unwrap();
        assert_eq!(o.state, newton.state, "n = {n}, {strategy:?}");
        assert_eq!(o.residuals, newton.residuals, "n = {n}, {strategy:?}");
    }
}

/// A period-2 shooting on the affine map finds its fixed point and reduces it to period 1
/// (the fixed point of P is a fixed point of P² too); the section points and the minimal
/// period of the steady-state search agree.
#[test]
fn a_fixed_point_shot_at_period_two_is_reduced_to_period_one() {
    let opts = ShootingOptions::default();
    let mut m = affine(0.5, -0.3);
    let want = m.fixed_point();
    let two = ShootingOptions { period: 2, ..opts };
    let o = shoot(&mut m, &DVector::zeros(3), &two).unwrap();
    assert_eq!(o.period, 1);
    assert!((&o.state - &want).amax() < 1e-12);
    let section = map_section_points(&mut m, &want, 3).unwrap();
    assert_eq!(section.len(), 3);
    for z in &section {
        assert!((z - &want).amax() < 1e-13);
    }
    assert_eq!(minimal_period(&mut m, &want, 4, 1e-10), 1);
    assert_eq!(minimal_period(&mut m, &DVector::zeros(3), 4, 1e-10), 4);
}

/// A state of the wrong length is refused by the trait's default check, naming it.
#[test]
fn a_guess_of_the_wrong_length_is_refused() {
    let mut m = affine(0.5, -0.3);
    let e = shoot(&mut m, &DVector::zeros(2), &ShootingOptions::default()).unwrap_err();
    assert!(
        matches!(
            e,
            SimError::StateLength {
                expected: 3,
                got: 2,
                ..
            }
        ),
        "{e:?}"
    );
}

/// The paper's linear model with the sample out of reach (α5 = 5): the stroboscopic map's
/// period-1 orbit is the harmonic forced response, its multipliers e^{λT}.
#[test]
fn stroboscopic_map_of_the_linear_model_has_the_harmonic_orbit() {
    let p = Params {
        alpha5: 5.0,
        ..Params::default()
    };
    let model = CantileverModel::new(&p).unwrap();
    let mut it = build(&model, IntegratorOptions::default(), 0.0, &model.rest()).unwrap();
    let want = harmonic_response(&model, Region::Free, 0.0);
    let eig = model.dynamics(Region::Free).a.complex_eigenvalues();
    let mu: Vec<Complex<f64>> = eig.iter().map(|l| (l * p.period()).exp()).collect();
    let mut map = StroboscopicMap::new(it.as_mut(), 1);
    assert_eq!(DiscreteMap::dim(&map), model.dim());
    assert_eq!(DiscreteMap::periods(&map), 1);
    assert_eq!(DiscreteMap::duration(&map), p.period());
    let o = shoot(&mut map, &model.rest(), &ShootingOptions::default()).unwrap();
    assert!((&o.state - &want).amax() < 1e-9 * (1.0 + want.amax()));
    assert_multipliers(&o.multipliers, &mu, 1e-9);
    assert!(o.stable);
    assert_eq!(o.switchings, 0);
    // a second solve on the integrator (a new map over it) is the same, bit for bit
    let mut map = StroboscopicMap::new(it.as_mut(), 1);
    let again = shoot(&mut map, &model.rest(), &ShootingOptions::default()).unwrap();
    assert_eq!(again, o);
}

/// The trait's Pᵏ of a period-n stroboscopic map is the inherent map of k·n periods, bit for
/// bit: images, Jacobians, distances to grazing (the analyses' numbers do not change by going
/// through the trait).
#[test]
fn the_trait_is_the_stroboscopic_maps_own_numbers() {
    let model = CantileverModel::new(&Params::default()).unwrap();
    let mut it = build(&model, IntegratorOptions::default(), 0.0, &model.rest()).unwrap();
    let z = model.rest();
    let plain = StroboscopicMap::new(it.as_mut(), 2).apply(&z).unwrap();
    let image = StroboscopicMap::new(it.as_mut(), 2).image(&z).unwrap();
    let grazing = StroboscopicMap::new(it.as_mut(), 2)
        .grazing_distance(&z)
        .unwrap();
    let unwatched = StroboscopicMap::new(it.as_mut(), 2)
        .watch_grazing(false)
        .apply(&z)
        .unwrap();
    for (periods, k) in [(1, 2), (2, 1)] {
        let mut map = StroboscopicMap::new(it.as_mut(), periods);
        let dmap: &mut dyn DiscreteMap = &mut map;
        assert_eq!(dmap.linearise(&z, k, true).unwrap(), plain);
        assert_eq!(dmap.iterate(&z, k).unwrap(), image);
        assert_eq!(
            dmap.grazing_distance(&z, k).unwrap().to_bits(),
            grazing.to_bits()
        );
        let u = dmap.linearise(&z, k, false).unwrap();
        assert_eq!(
            (u.state, u.jacobian),
            (unwatched.state.clone(), unwatched.jacobian.clone())
        );
        assert!(dmap.closes(&z, k).unwrap());
    }
}

//! The linear response of a periodic orbit to the thermal force: the chain of the deviations
//! from the orbit over its period, their stationary covariance at the period's start and their
//! covariance at any time of it. The lock-in's noise ([`super::lock_in_noise`]) and a PeakForce
//! tap's ([`super::peakforce::tap_noise`]) are read from it.
//!
//! **The chain.** Small deviations δz from the period-n orbit z*(τ) obey the variational
//! equations with the saltation matrix at each switching (Leine & Nijmeijer 2004, ch. 7), driven
//! by the fluctuation–dissipation theorem's white force, the diffusion D = GGᵀ of the
//! stochastic step ([`crate::integrate::exact::noise`]; the region's damping under the linear
//! law, the lever's and the medium's under a nonlinear one). Under SLS the Maxwell arm's dashpot
//! α6 adds its own force, white with 2 k_BT α6 (the same theorem), on its extension u:
//! D_uu = 2 k_BT/α6, in and out of contact (α6 u̇ = κ(δ_s − u) + f, [`crate::contact::Zener`]),
//! so that a lever held in contact fluctuates as equipartition over the lever and the arm gives,
//! ⟨δx²⟩ = k_BT/(k + α4) (the relaxed spring). Over a part (τ_a, τ_b) of the
//! period δz ↦ Φ δz + ξ, Φ = Φ(τ_b, τ_a) the flow's Jacobian ([`crate::maps::flow`]: the step
//! Jacobians and the saltation matrices) and ξ Gaussian with covariance
//! ∫ Φ(τ_b,s) D Φ(τ_b,s)ᵀ ds. That integral is exact (Van Loan's block exponential,
//! [`crate::integrate::exact::noise`]) over a part without a switching where the motion is
//! linear (the linear law and SLS, with its internal state, in either region; free flight under
//! a law that does not act outside contact); elsewhere it is the trapezoid rule
//! h/2 (Φ D_a Φᵀ + D_b), whose relative error is (ωh)²/12 for a motion of rate ω: parts of
//! ωh ≤ [`ETA`] = 2π/512 put it near 10⁻⁵.
//! Observer states (a lock-in's sums) extend the deviation: the chain is y ↦ F y + ξ over the
//! period, F the product of the parts' maps and ξ's covariance W the noise of every part carried
//! through every later map. The stationary covariance Y = F Y Fᵀ + W (the discrete Lyapunov
//! equation) is summed by doubling, Y = Σ_k F^k W F^kᵀ (R. A. Smith, "Matrix equation
//! XA + BX = C", *SIAM J. Appl. Math.* 16 (1968) 198–201); at a time t of the period the
//! covariance is F_t Y F_tᵀ + W_t, (F_t, W_t) the chain from the period's start to t.
//!
//! The laws whose region depends on the history as well (JKR's neck and the capillary meniscus,
//! left at another distance than they formed) are followed by carrying the region from part to
//! part: each part restarts the integrator in the region the last one ended in
//! ([`crate::maps::flow::flow_in`]), the walk's start in the one the orbit's shooting starts it
//! in ([`crate::system::HybridSystem::mode_at`]).
//!
//! The impact law's jumps are the flow's saltation matrices (Leine & Nijmeijer 2004, ch. 7). While
//! it sticks, the constraint's reaction takes the thermal force's part at the tip (the diffusion
//! projected onto no tip acceleration, [`state_diffusion`]), and the motion is affine with the
//! sticking field's Jacobian
//! (the constraint held by its Baumgarte terms), so its parts are exact too. A beam pinned so
//! at its tip fluctuates as equipartition conditioned on φᵀa fixed.
//!
//! This is the linear response of the measurement itself. It holds while σ stays small against
//! the orbit's distance to grazing (a switching that the noise can remove or add is outside any
//! linearisation), and only for a stable orbit (an unstable one has no stationary covariance).
//! Units are the model's: τ (eq. 5), lengths in g₀, k_B T in the model's energy unit.

use crate::contact::ForceEval;
use crate::error::SimError;
use crate::galerkin::Region;
use crate::integrate::exact::noise::{linear_part, rate_of, state_diffusion, van_loan};
use crate::integrate::{build, Integrator, IntegratorOptions};
use crate::maps::flow::{flow_in, FlowMap};
use crate::model::CantileverModel;
use crate::system::HybridSystem;
use nalgebra::{DMatrix, DVector};

/// The largest ωh of a part whose noise is summed by the trapezoid rule (module docs): 512 parts
/// per period of the motion's rate ω.
pub const ETA: f64 = std::f64::consts::TAU / 512.0;

/// The doubling's iterations at most: F^(2^k) has gone below 10⁻¹⁵ of the unit for any stable
/// chain whose slowest decay per period is 1 − 10⁻¹⁵ or faster.
const DOUBLINGS: usize = 64;

/// Within how many of the free lever's thermal standard deviations √(k_BT c_s) of the surface
/// (c_s its static compliance at the tip) an orbit's lowest point may pass, above it or inside
/// it, before the noise changes its contacts from period to period: a linear response there is
/// beyond its validity ([`grazing`]).
pub(crate) const NOISE_GRAZING: f64 = 5.0;

/// How many of the orbits on `base` of observables `orbits` pass within [`NOISE_GRAZING`]
/// thermal standard deviations of the surface at k_B T = `kt`: their lowest point's tip–sample
/// distance (g₀) within NOISE_GRAZING √(k_BT c_s) of it. An impacting orbit of the impact law
/// always reaches the surface; its own grazing is an impact at vanishing speed (Nordmark 1991),
/// so it counts where its impacts' root-mean-square speed v, from their kinetic-energy loss
/// ½ m_eff (1 − r²) v² each, is below NOISE_GRAZING thermal speeds √(k_BT/m_eff) (always for
/// r = 1, which loses none).
///
/// # Errors
/// The model's.
pub(crate) fn grazing<'o>(
    base: &crate::Params,
    kt: f64,
    orbits: impl Iterator<Item = &'o crate::analysis::observables::Observables>,
) -> Result<usize, SimError> {
    let model = CantileverModel::new(base)?;
    let sigma = (kt * crate::analysis::peakforce::static_compliance(&model)).sqrt();
    let offset = base.contact_law.distance_offset();
    let (restitution, m_eff) = (base.contact_law.restitution(), model.effective_mass());
    let near = |o: &crate::analysis::observables::Observables| match restitution {
        Some(r) if o.impacts_per_period > 0.0 => {
            let v2 = 2.0 * o.impact_loss / (o.impacts_per_period * m_eff * (1.0 - r * r));
            // NaN (r = 1: no loss to read the speed from) counts
            v2.is_nan() || v2 < NOISE_GRAZING * NOISE_GRAZING * kt / m_eff
        }
        _ => (o.min_distance - offset).abs() < NOISE_GRAZING * sigma,
    };
    Ok(orbits.filter(|o| near(o)).count())
}

/// The chain y ↦ F y + ξ, ξ ~ N(0, W), from the period's start to the walk's time (module docs).
#[derive(Debug, Clone)]
pub(crate) struct Chain {
    /// F, (2N + observers)².
    pub f: DMatrix<f64>,
    /// W, the noise injected so far carried to the walk's time.
    pub w: DMatrix<f64>,
}

impl Chain {
    /// F ← M F, W ← M W Mᵀ: a linear map `m` of the deviation and the observers.
    pub(crate) fn apply(&mut self, m: &DMatrix<f64>) {
        self.f = m * &self.f;
        self.w = m * &self.w * m.transpose();
    }

    /// The stationary covariance Y = F Y Fᵀ + W by doubling (module docs): `None` where
    /// F^(2^k) does not go to zero (an unstable or marginal chain).
    pub(crate) fn stationary(&self) -> Option<DMatrix<f64>> {
        let (mut a, mut y) = (self.f.clone(), self.w.clone());
        for _ in 0..DOUBLINGS {
            y += &a * &y * a.transpose();
            a = &a * &a;
            let size = a.amax();
            if !size.is_finite() || size > 1e12 {
                return None;
            }
            if size < 1e-15 {
                return Some(0.5 * (&y + y.transpose()));
            }
        }
        None
    }

    /// gᵀ(F Y Fᵀ + W)g: the variance of the linear form g of the deviation at the walk's time,
    /// `y` the stationary covariance at the period's start.
    pub(crate) fn variance(&self, y: &DMatrix<f64>, g: &DVector<f64>) -> f64 {
        let fg = self.f.transpose() * g;
        (fg.dot(&(y * &fg)) + g.dot(&(&self.w * g))).max(0.0)
    }
}

/// The walk along the orbit that builds the [`Chain`] part by part.
pub(crate) struct Walk<'a> {
    model: &'a CantileverModel,
    /// The lever without the sample (its A_s and the diffusion's damping).
    linear: CantileverModel,
    /// Per region, whether the motion is affine with the model's own matrix (its Jacobian):
    /// SLS in both regions (with its internal state), the impact law's sticking (module docs).
    own_matrix: [bool; 2],
    integ: Box<dyn Integrator>,
    /// D per region.
    d: [DMatrix<f64>; 2],
    /// The region at `tau`.
    pub region: Region,
    /// The law's tip force at `tau` (its value and partials).
    pub force: ForceEval,
    /// ∂F_c/∂u at `tau`: its rate on SLS's internal state (0 under the other laws).
    pub force_u: f64,
    /// F's map of a part: the flow's Jacobian in its top-left block, the unit elsewhere.
    map: DMatrix<f64>,
    /// The exact noise of the last part length of each region, (ℓ, Q).
    exact: [Option<(f64, DMatrix<f64>)>; 2],
    /// τ of the walk.
    pub tau: f64,
    /// The orbit's state at `tau`.
    pub state: DVector<f64>,
    /// The chain from the start to `tau`.
    pub chain: Chain,
}

impl<'a> Walk<'a> {
    /// The walk from (0, `z`) on `model` at k_B T = `kt` (model units), the chain's deviation
    /// followed by `observers` states.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `kt` (negative or not finite); the integrator's.
    pub(crate) fn new(
        model: &'a CantileverModel,
        z: &DVector<f64>,
        kt: f64,
        observers: usize,
        options: IntegratorOptions,
    ) -> Result<Self, SimError> {
        if !(kt.is_finite() && kt >= 0.0) {
            return Err(SimError::out_of_range(
                "kt",
                kt,
                "must be a finite number ≥ 0",
            ));
        }
        let linear = linear_part(model)?;
        // SLS (the dashpot's own force on u, `state_diffusion`) and sticking: exact parts over
        // the model's own matrix (module docs)
        let zener = model.params().contact_law.internal_states() > 0;
        let sticks = model.params().contact_law.restitution().is_some();
        // (sticking's projected onto no tip acceleration, `state_diffusion`)
        let d = [Region::Free, Region::Contact].map(|r| state_diffusion(model, &linear, r, kt));
        let n = z.len() + observers;
        let (region, force, force_u) = tip_force(model, 0.0, z, model.mode_at(0.0, z.as_slice()));
        Ok(Walk {
            integ: build(model, options, 0.0, z)?,
            linear,
            own_matrix: [zener, zener || sticks],
            d,
            region,
            force,
            force_u,
            map: DMatrix::identity(n, n),
            exact: [None, None],
            tau: 0.0,
            state: z.clone(),
            chain: Chain {
                f: DMatrix::identity(n, n),
                w: DMatrix::zeros(n, n),
            },
            model,
        })
    }

    /// The part to `t1` (module docs).
    ///
    /// # Errors
    /// The flow's.
    pub(crate) fn part(&mut self, t1: f64) -> Result<(), SimError> {
        let fl = self.flow(t1)?;
        let at = tip_force(self.model, t1, &fl.state, self.integ.region());
        self.take(fl, t1, at);
        Ok(())
    }

    /// A part toward `end` of at most `h` and of ω_c ℓ ≤ [`ETA`] at both its ends (ω_c the
    /// contact's rate, [`rate_of`]; halved until it holds, to ℓ ≥ 10⁻⁹ h): the parts of a
    /// walk whose times are free.
    ///
    /// # Errors
    /// The flow's.
    pub(crate) fn adaptive_part(&mut self, end: f64, h: f64) -> Result<(), SimError> {
        let m_eff = self.model.effective_mass();
        let mut len = h.min(ETA / rate_of(&self.force, m_eff)).min(end - self.tau);
        loop {
            let t1 = if len >= end - self.tau {
                end
            } else {
                self.tau + len
            };
            let fl = self.flow(t1)?;
            let at = tip_force(self.model, t1, &fl.state, self.integ.region());
            if len * rate_of(&at.1, m_eff) <= ETA || len < 1e-9 * h {
                self.take(fl, t1, at);
                return Ok(());
            }
            len *= 0.5;
        }
    }

    /// The flow from the walk's time to `t1`, in the walk's region.
    fn flow(&mut self, t1: f64) -> Result<FlowMap, SimError> {
        let start = (self.tau, &self.state, self.region);
        flow_in(self.integ.as_mut(), start, t1)
    }

    /// Whether the motion in `r` is linear (module docs).
    fn linear_in(&self, r: Region) -> bool {
        let law = self.model.law();
        law.is_affine() || self.own_matrix[r.index()] || (r == Region::Free && !law.acts_outside())
    }

    /// Take the part to `t1` of flow `fl`, ending in region `to` under the tip force `force`
    /// (and its rate on u, [`tip_force`]): F ← M F, W ← M W Mᵀ + (the part's noise, module
    /// docs) on the deviation.
    fn take(&mut self, fl: FlowMap, t1: f64, (to, force, force_u): (Region, ForceEval, f64)) {
        let (h, from, dim) = (t1 - self.tau, self.region, fl.state.len());
        let exact = fl.switchings == 0 && from == to && self.linear_in(from);
        self.map
            .view_mut((0, 0), (dim, dim))
            .copy_from(&fl.jacobian);
        self.chain.apply(&self.map);
        let mut top = self.chain.w.view_mut((0, 0), (dim, dim));
        if exact {
            let i = from.index();
            if !matches!(&self.exact[i], Some((l, _)) if *l == h) {
                // SLS's region matrix holds its internal state's rows, the sticking one the
                // constraint's (the model's Jacobian, constant in each region)
                let (_, q) = if self.own_matrix[i] {
                    let mut a = DMatrix::zeros(dim, dim);
                    (self.model).jacobian_into(from, self.tau, self.state.as_slice(), &mut a);
                    van_loan(&a, &self.d[i], h)
                } else {
                    van_loan(&self.linear.dynamics(from).a, &self.d[i], h)
                };
                self.exact[i] = Some((h, q));
            }
            top += &self.exact[i].as_ref().expect("set above").1;
        } else {
            let j = &fl.jacobian;
            top += (j * &self.d[from.index()] * j.transpose() + &self.d[to.index()]) * (0.5 * h);
        }
        (self.state, self.tau, self.region) = (fl.state, t1, to);
        (self.force, self.force_u) = (force, force_u);
    }
}

/// The law's tip force at (τ, `z`) in region `r` of `model` and its rate ∂F_c/∂u on SLS's
/// internal state u (0 under the other laws): in contact F_c = α4 δ + κ(δ − u)
/// ([`crate::contact::Zener::force`]), ∂F_c/∂δ = α4 + κ, ∂F_c/∂u = −κ.
fn tip_force(
    model: &CantileverModel,
    tau: f64,
    z: &DVector<f64>,
    r: Region,
) -> (Region, ForceEval, f64) {
    if let (Some(zn), Region::Contact) = (model.zener(), r) {
        let (delta, u) = (-model.v_t(tau, z), z[2 * model.modes()]);
        let (force, d_delta) = (zn.force(true, delta, u), zn.relaxed + zn.maxwell);
        let e = ForceEval {
            force,
            d_delta,
            d_rate: 0.0,
        };
        return (r, e, -zn.maxwell);
    }
    let e = model.tip_force_eval(r, model.base_trig(tau), z.as_slice());
    (r, e, 0.0)
}

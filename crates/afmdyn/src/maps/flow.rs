//! The flow map z(τ0) ↦ z(τ1) and its Jacobian (over τ1 − τ0 = nT, the monodromy matrix of
//! the period-n stroboscopic map, which [`crate::maps::StroboscopicMap`] applies): the product
//! of the step Jacobians of any integrator that provides them (the exact transition matrices
//! e^{A_s t}, or the adaptive integrator's variational equations) and the saltation matrix of
//! every event ([`crate::system::saltation`]; Leine & Nijmeijer 2004, ch. 7).

use crate::error::SimError;
use crate::galerkin::Region;
use crate::integrate::exact::matmul_into;
use crate::integrate::{Integrator, Step, SwitchEvent};
use crate::params::SweepParam;
use crate::roots::extremum;
use crate::system::{saltation_parts, EventKind};
use nalgebra::{DMatrix, DVector};

/// The flow map over [τ0, τ1] with its Jacobian.
#[derive(Debug, Clone, PartialEq)]
pub struct FlowMap {
    /// z(τ1), shape `[2N]`.
    pub state: DVector<f64>,
    /// ∂z(τ1)/∂z(τ0), 2N×2N.
    pub jacobian: DMatrix<f64>,
    /// Number of events (switchings, impacts, sticking, releases).
    pub switchings: usize,
    /// Contacts: entries into region II and impacts.
    pub contacts: usize,
    /// Smallest |V_T| at a local extremum of V_T, and smallest |dV_T/dτ| at an event (scaled by
    /// 1/Ω): how close the trajectory is to grazing the sample. NaN from a map that does not
    /// watch it ([`crate::maps::StroboscopicMap::watch_grazing`]).
    pub grazing_distance: f64,
    /// Time spent in region II (contact, or sticking for the impact law).
    pub contact_time: f64,
    /// ln|det ∂z(τ1)/∂z(τ0)| = Σ ln|det J_step| + Σ ln|det S|: the log of the phase-volume
    /// change (for an affine region ln det e^{A t} = t trace A, Liouville), from one determinant
    /// of the product.
    pub log_volume: f64,
    /// ∂z(τ1)/∂p at fixed τ1, shape `[2N]`, when asked for (`flow`) and
    /// the integrator provides it ([`crate::integrate::AffineRegions::last_step_param_derivative_into`] per step,
    /// [`crate::integrate::AffineRegions::region_particular_param_derivative_into`] per stint); else `None`.
    pub param_derivative: Option<DVector<f64>>,
}

/// Integrate (τ0, z0) → τ1 with `integ`, multiplying the step Jacobians and saltation
/// matrices, with the distance to grazing when `grazing` (else NaN) and, for `param`, the
/// parameter sensitivity s = ∂z(τ1)/∂p at fixed τ1 in [`FlowMap::param_derivative`]: s(τ0) =
/// 0, s ← J s + ∂z(τ_b)/∂p|_{z(τ_a)} over each step (variational equation of the parameter,
/// Hairer, Nørsett & Wanner, *Solving ODEs I*, §I.14) — over a whole stint at once in an
/// affine region
/// ([`crate::integrate::AffineRegions::region_particular_param_derivative_into`]) — and
/// s⁺ = S s⁻ + w ∂g/∂p at each event (`crate::system::saltation_with_shift`); `None` there
/// when the integrator or the law does not provide it (then ∂z/∂p needs finite differences).
/// The one loop of every flow with a Jacobian ([`crate::maps::StroboscopicMap::apply`]).
/// Switches the integrator's variational equations on.
///
/// # Errors
/// [`SimError`] from the integrator, [`SimError::Unsupported`] for one without step Jacobians.
pub(crate) fn flow(
    integ: &mut dyn Integrator,
    tau0: f64,
    z0: &DVector<f64>,
    tau1: f64,
    param: Option<SweepParam>,
    grazing: bool,
) -> Result<FlowMap, SimError> {
    flow_from(integ, (tau0, z0, None), tau1, param, grazing)
}

/// [`flow`] from (τ0, z0) in `region` as given ([`Integrator::reset_in`]: no projection), with
/// neither a parameter sensitivity nor the distance to grazing: a flow continued in parts,
/// each in the region the last one ended in (a hysteretic law's neck or meniscus, which the
/// state alone does not tell).
///
/// # Errors
/// As [`flow`].
pub(crate) fn flow_in(
    integ: &mut dyn Integrator,
    (tau0, z0, region): (f64, &DVector<f64>, Region),
    tau1: f64,
) -> Result<FlowMap, SimError> {
    flow_from(integ, (tau0, z0, Some(region)), tau1, None, false)
}

/// [`flow`] from (τ0, z0), reset in the region given or else by [`Integrator::reset`].
fn flow_from(
    integ: &mut dyn Integrator,
    (tau0, z0, region): (f64, &DVector<f64>, Option<Region>),
    tau1: f64,
    param: Option<SweepParam>,
    grazing: bool,
) -> Result<FlowMap, SimError> {
    integ.set_variational(true);
    match region {
        Some(r) => integ.reset_in(tau0, z0, r)?,
        None => integ.reset(tau0, z0)?,
    }
    let mut product = Product::start(integ, (tau0, z0, region.is_none()), param);
    let mut out = FlowMap {
        state: z0.clone(),
        jacobian: DMatrix::zeros(0, 0),
        switchings: 0,
        contacts: 0,
        grazing_distance: if grazing { f64::INFINITY } else { f64::NAN },
        contact_time: 0.0,
        log_volume: 0.0,
        param_derivative: None,
    };
    let mut before = z0.clone();
    while integ.tau() < tau1 {
        before.copy_from(integ.state());
        let step = integ.step(tau1)?;
        let len = step.tau1 - step.tau0;
        if len <= 0.0 && step.event.is_none() {
            continue;
        }
        product.step(integ, &step)?;
        if step.region == Region::Contact {
            out.contact_time += len;
        }
        if grazing {
            watch_grazing(integ, &step, &before, &mut out.grazing_distance);
        }
        if let Some(e) = &step.event {
            product.close_stint(integ, e.tau)?;
            product.event(integ, e);
            out.switchings += 1;
            if e.to == Region::Contact || e.kind == EventKind::Impact {
                out.contacts += 1;
            }
        }
    }
    let tau = integ.tau();
    product.close_stint(integ, tau)?;
    out.state = integ.state().clone();
    out.param_derivative = product.param.map(|_| product.sens);
    out.log_volume = product.jac.clone().lu().determinant().abs().ln();
    out.jacobian = product.jac;
    Ok(out)
}

/// The Jacobian M and the parameter sensitivity s of a flow as [`flow`] multiplies them up step
/// by step, with their scratch (no allocation per step).
struct Product {
    /// M so far.
    jac: DMatrix<f64>,
    /// The step Jacobian, or a stint's transition matrix.
    step_jac: DMatrix<f64>,
    /// The product's scratch.
    prod: DMatrix<f64>,
    /// The parameter of s, `None` once a step or an event does not provide its derivative.
    param: Option<SweepParam>,
    /// s so far.
    sens: DVector<f64>,
    /// The step's ∂z/∂p, or ∂z_p/∂p at the open stint's start.
    step_dp: DVector<f64>,
    /// Scratch of s.
    tmp: DVector<f64>,
    /// The open stint (region, start time) whose Jacobian is taken at its end.
    stint: Option<(Region, f64)>,
}

impl Product {
    /// M = I (or, for a start that is `projected`, the projection's Jacobian of a start inside
    /// a rigid sample, whose own parameter dependence is not modelled: no s then), s = 0.
    fn start(
        integ: &dyn Integrator,
        (tau0, z0, projected): (f64, &DVector<f64>, bool),
        mut param: Option<SweepParam>,
    ) -> Self {
        let dim = z0.len();
        // a start inside a rigid sample is first projected onto it (impact law): its Jacobian
        let projection = projected.then(|| integ.system().start_projection(tau0, z0));
        let jac = match projection.flatten() {
            Some((_, p)) => {
                // the projection's own parameter dependence is not modelled
                param = None;
                p
            }
            None => DMatrix::identity(dim, dim),
        };
        Product {
            jac,
            step_jac: DMatrix::zeros(dim, dim),
            prod: DMatrix::zeros(dim, dim),
            param,
            sens: DVector::zeros(dim),
            step_dp: DVector::zeros(dim),
            tmp: DVector::zeros(dim),
            stint: None,
        }
    }

    /// The step taken: a stint opened in a region with a transition matrix for any duration
    /// (affine, [`crate::integrate::AffineRegions::region_transition_into`]), which takes one
    /// Jacobian e^{A_r t} at its end instead of one product per step, and over which the
    /// parameter sensitivity telescopes
    /// ([`crate::integrate::AffineRegions::region_particular_param_derivative_into`]: ∂z_p/∂p
    /// at its start now); else M ← J M and s ← J s + ∂z/∂p of the step.
    fn step(&mut self, integ: &mut dyn Integrator, step: &Step) -> Result<(), SimError> {
        if self.stint.is_none()
            && integ
                .affine()
                .is_some_and(|a| a.has_region_transition(step.region))
        {
            let open = match self.param {
                Some(p) => match integ.affine() {
                    Some(a) => a.region_particular_param_derivative_into(
                        p,
                        step.region,
                        step.tau0,
                        &mut self.step_dp,
                    )?,
                    None => false,
                },
                None => true,
            };
            if open {
                self.stint = Some((step.region, step.tau0));
            }
        }
        if self.stint.is_none() {
            integ.last_step_jacobian_into(&mut self.step_jac)?;
            left_mul(&self.step_jac, &mut self.jac, &mut self.prod);
            if let Some(p) = self.param {
                let given = match integ.affine() {
                    Some(a) => a.last_step_param_derivative_into(p, &mut self.step_dp)?,
                    None => false,
                };
                if given {
                    self.tmp.gemv(1.0, &self.step_jac, &self.sens, 0.0);
                    self.sens.copy_from(&self.tmp);
                    self.sens += &self.step_dp;
                } else {
                    self.param = None;
                }
            }
        }
        Ok(())
    }

    /// The open stint, if any, closed at its end `tau`: M ← e^{A_r t} M
    /// ([`crate::integrate::AffineRegions::region_transition_into`], which
    /// [`crate::integrate::AffineRegions::has_region_transition`] promised) and
    /// s ← e^{A_r t}(s − ∂z_p/∂p(τ0)) + ∂z_p/∂p(τ) (see
    /// [`crate::integrate::AffineRegions::region_particular_param_derivative_into`]).
    fn close_stint(&mut self, integ: &mut dyn Integrator, tau: f64) -> Result<(), SimError> {
        let Some((r, t0)) = self.stint.take() else {
            return Ok(());
        };
        let done = integ
            .affine()
            .is_some_and(|a| a.region_transition_into(r, tau - t0, &mut self.step_jac));
        debug_assert!(done, "has_region_transition promised the transition");
        left_mul(&self.step_jac, &mut self.jac, &mut self.prod);
        if let Some(p) = self.param {
            self.sens -= &self.step_dp;
            self.tmp.gemv(1.0, &self.step_jac, &self.sens, 0.0);
            let done = match integ.affine() {
                Some(a) => a.region_particular_param_derivative_into(p, r, tau, &mut self.sens)?,
                None => false,
            };
            debug_assert!(done, "provided at the stint's start");
            self.sens += &self.tmp;
        }
        Ok(())
    }

    /// M ← S M and s ← S s + w ∂g/∂p at the event `e`, S = R + w ∇gᵀ applied as a rank-one
    /// update.
    fn event(&mut self, integ: &dyn Integrator, e: &SwitchEvent) {
        let salt = saltation_parts(integ.system(), e.from, e.tau, e.state.as_slice());
        salt.apply(self.jac.as_mut_slice());
        if let Some(p) = self.param {
            match integ.system().guard_param_derivative(e.from, p, e.tau) {
                Some(dg) => {
                    salt.apply(self.sens.as_mut_slice());
                    self.sens.axpy(dg, &salt.shift, 1.0);
                }
                None => self.param = None,
            }
        }
    }
}

/// M ← J M: the product rule of the monodromy matrix M = Π S_k Φ_k (Leine & Nijmeijer 2004,
/// ch. 7), into the scratch matrix `prod` and swapped back (2N×2N products: fixed-size column
/// kernels up to 12×12, whose products do not pack or allocate).
fn left_mul(j: &DMatrix<f64>, m: &mut DMatrix<f64>, prod: &mut DMatrix<f64>) {
    matmul_into(j, m, 1.0, prod);
    std::mem::swap(m, prod);
}

/// Lower `nearest` to the distance to grazing within `step` (from `before`, the state at its
/// start): |V_T| at a local extremum of V_T inside the step, searched where dV_T/dτ changes sign
/// between its ends (V_T at the ends only to rule an extremum out once a distance is known,
/// [`farther`]), and |dV_T/dτ|/Ω at an event that ends it.
fn watch_grazing(
    integ: &mut dyn Integrator,
    step: &Step,
    before: &DVector<f64>,
    nearest: &mut f64,
) {
    let (d0, search) = {
        let m = integ.system();
        let (tau_b, z_b) = match &step.event {
            Some(e) => (e.tau, &e.state),
            None => (step.tau1, integ.state()),
        };
        let (d0, d1) = (m.v_t_dot(step.tau0, before), m.v_t_dot(tau_b, z_b));
        let search = step.tau1 > step.tau0
            && (d0 > 0.0) != (d1 > 0.0)
            && !(nearest.is_finite()
                && farther(m.v_t(step.tau0, before), m.v_t(tau_b, z_b), d0, *nearest));
        (d0, search)
    };
    if search {
        let mut vt = |t: f64| integ.dense_v_t(t);
        let t = extremum(step.tau0, step.tau1, d0, &mut vt);
        *nearest = nearest.min(vt(t)[0].abs());
    }
    if let Some(e) = &step.event {
        *nearest = nearest.min(e.v_t_dot.abs() / integ.system().omega());
    }
}

/// Whether the local extremum of V_T inside a step (V_T = `va`, `vb` at its ends, V_T' = `d0` at
/// its start) is provably no nearer to V_T = 0 than `nearest`: with σ = +1 for a maximum and
/// −1 for a minimum, σV_T(t*) ≥ max(σV_a, σV_b) (a maximum lies above both ends of its step, a
/// minimum below both), so when max(σV_a, σV_b) ≥ `nearest` ≥ 0, |V_T(t*)| ≥ `nearest` too and
/// the extremum search cannot lower the grazing distance (up to the round-off of the located
/// extremum).
fn farther(va: f64, vb: f64, d0: f64, nearest: f64) -> bool {
    let sigma = if d0 > 0.0 { 1.0 } else { -1.0 };
    (sigma * va).max(sigma * vb) >= nearest
}

/// The distance to grazing of the flow from (τ0, z0) to τ1 ([`FlowMap::grazing_distance`]),
/// without the Jacobian: the same steps as [`flow`] (variational equations
/// switched on as there) and the same searches, so the same value.
///
/// # Errors
/// [`SimError`] from the integrator.
pub(crate) fn grazing_distance(
    integ: &mut dyn Integrator,
    tau0: f64,
    z0: &DVector<f64>,
    tau1: f64,
) -> Result<f64, SimError> {
    integ.set_variational(true);
    integ.reset(tau0, z0)?;
    let mut before = z0.clone();
    let mut nearest = f64::INFINITY;
    while integ.tau() < tau1 {
        before.copy_from(integ.state());
        let step = integ.step(tau1)?;
        if step.tau1 <= step.tau0 && step.event.is_none() {
            continue;
        }
        watch_grazing(integ, &step, &before, &mut nearest);
    }
    Ok(nearest)
}

/// The state z(τ1) of the flow from (τ0, z0) alone, with the variational equations switched
/// off (an integrator whose step control sees them — the adaptive one — then takes its own
/// steps, a seventh of the work of a variational step at N = 3): for finite differences of the
/// map, whose flows must all take steps chosen alike, not for the `state` of
/// `flow`.
///
/// # Errors
/// [`SimError`] from the integrator.
pub fn flow_state(
    integ: &mut dyn Integrator,
    tau0: f64,
    z0: &DVector<f64>,
    tau1: f64,
) -> Result<DVector<f64>, SimError> {
    integ.set_variational(false);
    integ.reset(tau0, z0)?;
    crate::integrate::advance(integ, tau1)?;
    Ok(integ.state().clone())
}

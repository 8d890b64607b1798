//! The stroboscopic map P(z) = z(τ0 + nT) and its Jacobian (the monodromy matrix of the
//! period-n map): the product of the exact segment propagators e^{A_s t} and the saltation
//! matrices at every switching ([`CantileverModel::saltation`]).

use super::steady::extremum;
use crate::error::SimError;
use crate::galerkin::Region;
use crate::integrate::exact::ExactPropagator;
use crate::integrate::Integrator;
use crate::model::CantileverModel;
use nalgebra::{DMatrix, DVector};

/// The flow map over [τ0, τ1] with its Jacobian.
#[derive(Debug, Clone, PartialEq)]
pub struct FlowMap {
    /// z(τ1), shape `[2N]`.
    pub state: DVector<f64>,
    /// ∂z(τ1)/∂z(τ0), 2N×2N.
    pub jacobian: DMatrix<f64>,
    /// Number of switchings.
    pub switchings: usize,
    /// Contacts (entries into region II).
    pub contacts: usize,
    /// Smallest |V_T| at a local extremum of V_T, and smallest |dV_T/dτ| at a switching
    /// (scaled by 1/Ω): how close the trajectory is to grazing the sample.
    pub grazing_distance: f64,
    /// Time spent in contact.
    pub contact_time: f64,
    /// ∫ trace A_s dτ + Σ log|det S| (log of the phase-volume change; Liouville).
    pub log_volume: f64,
}

/// Trace of each region's state matrix, [free, contact].
fn traces(model: &CantileverModel) -> [f64; 2] {
    [Region::Free, Region::Contact].map(|r| model.dynamics(r).a.trace())
}

/// Integrate (τ0, z0) → τ1 with `prop`, multiplying the step Jacobians and saltation matrices.
///
/// # Errors
/// [`SimError`] from the propagator.
pub fn flow_with_jacobian(
    prop: &mut ExactPropagator,
    tau0: f64,
    z0: &DVector<f64>,
    tau1: f64,
) -> Result<FlowMap, SimError> {
    prop.reset(tau0, z0)?;
    let model = prop.model().clone();
    let p = *model.params();
    let tr = traces(&model);
    let dim = model.dim();
    let mut jac = DMatrix::identity(dim, dim);
    let mut out = FlowMap {
        state: z0.clone(),
        jacobian: DMatrix::zeros(0, 0),
        switchings: 0,
        contacts: 0,
        grazing_distance: f64::INFINITY,
        contact_time: 0.0,
        log_volume: 0.0,
    };
    let mut before = z0.clone();
    while prop.tau() < tau1 {
        before.copy_from(prop.state());
        let step = prop.step(tau1)?;
        let len = step.tau1 - step.tau0;
        if len <= 0.0 && step.event.is_none() {
            continue;
        }
        jac = prop.last_step_jacobian() * jac;
        out.log_volume += tr[step.region.index()] * len;
        if step.region == Region::Contact {
            out.contact_time += len;
        }
        // local extrema of V_T inside the step: distance to grazing
        let z1 = prop.state().clone();
        let (d0, d1) = (
            model.v_t_dot(step.tau0, &before),
            model.v_t_dot(step.tau1, &z1),
        );
        if len > 0.0 && (d0 > 0.0) != (d1 > 0.0) {
            let mut vt = |t: f64| prop.dense_v_t(t);
            let t = extremum(step.tau0, step.tau1, d0, &mut vt);
            out.grazing_distance = out.grazing_distance.min(vt(t)[0].abs());
        }
        if let Some(e) = &step.event {
            let s = model.saltation(e.from, e.to, e.tau, &e.state);
            out.log_volume += s.determinant().abs().ln();
            jac = s * jac;
            out.switchings += 1;
            if e.to == Region::Contact {
                out.contacts += 1;
            }
            out.grazing_distance = out.grazing_distance.min(e.v_t_dot.abs() / p.omega);
        }
    }
    out.state = prop.state().clone();
    out.jacobian = jac;
    Ok(out)
}

/// The period-n stroboscopic map from drive phase 0 (τ = 0 → nT) with its monodromy matrix.
///
/// # Errors
/// [`SimError`] from the propagator.
pub fn stroboscopic(
    prop: &mut ExactPropagator,
    z0: &DVector<f64>,
    n: usize,
) -> Result<FlowMap, SimError> {
    let t = n as f64 * prop.model().period();
    flow_with_jacobian(prop, 0.0, z0, t)
}

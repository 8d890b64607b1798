//! V_T (eq. 8) of a plain state, and the base-drive amplitude in it. (In a modal region V_T
//! comes from the homogeneous tip and the particular part: [`super::forcing`].)

use crate::model::CantileverModel;
use crate::params::Params;

/// Amplitude of the base-displacement term α2 sin Ωτ of V_T = W(1,τ) + α2 sin Ωτ + α5 (eq. 8):
/// [`Params::base_amplitude`] (0 for the point-mass model, whose base does not move).
pub(super) fn base_amp(p: &Params) -> f64 {
    p.base_amplitude()
}

/// [V_T, dV_T/dτ] (eq. 8) of a plain state `z: [f64; 2N]` as (a, ȧ) at a time with
/// (sin Ωτ, cos Ωτ) = `sc`: the tip deflection and rate Σ a_j φ_j(1), Σ ȧ_j φ_j(1) (as
/// [`CantileverModel::w_tip`]), then [`CantileverModel::v_t_at`].
#[inline(always)]
pub(super) fn tip_v_t(model: &CantileverModel, z: &[f64], sc: (f64, f64)) -> (f64, f64) {
    let n = z.len() / 2;
    let tip = model.tip().as_slice();
    let dot = |x: &[f64]| tip.iter().zip(x).map(|(a, b)| a * b).sum::<f64>();
    let [v, vd, _] = model.v_t_at(sc, [dot(&z[..n]), dot(&z[n..]), 0.0]);
    (v, vd)
}

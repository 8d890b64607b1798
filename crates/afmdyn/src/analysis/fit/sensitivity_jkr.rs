//! The JKR law's parameter derivatives for the exact orbit sensitivities
//! ([`super::sensitivity`]): ∂F_c/∂p at fixed (δ, δ̇) and the contact guard's ∂g/∂p, for the
//! gap α5, the Hertz group α4, the adhesion group P̃ and the Kelvin–Voigt group α6.
//!
//! # The force at fixed indentation
//! Johnson, Kendall & Roberts, *Proc. R. Soc. Lond. A* 324 (1971) 301, in the variable
//! q = (a²/R)^{1/4} of [`crate::contact::Jkr`] (module docs of `contact/jkr.rs`): in contact
//! F_c = α4 q⁶ − b q³ + α6 q² δ̇ with δ = q⁴ − c q, c = √(8P̃/(3α4)), b = √(6P̃α4) (the
//! Kelvin–Voigt damper α6 q² δ̇ ∝ the contact radius a = √R q², as DMT's); no force out of
//! contact. The indentation δ and its rate δ̇ are the state's (δ = −V_T), so a parameter moves
//! F_c at fixed (δ, δ̇) both directly and through the root q(δ; c):
//! ∂F_c/∂p|_δ = ∂F/∂p|_q + F_q ∂q/∂p|_δ, F_q = 6α4 q⁵ − 3b q² + 2α6 q δ̇, and, differentiating
//! q⁴ − c q = δ at fixed δ, ∂q/∂p|_δ = q (∂c/∂p)/(4q³ − c). With ∂b/∂α4 = b/(2α4),
//! ∂b/∂P̃ = b/(2P̃), ∂c/∂α4 = −c/(2α4), ∂c/∂P̃ = c/(2P̃):
//! * ∂F_c/∂α4|_δ = q⁶ − (b/(2α4)) q³ − F_q q c/(2α4 (4q³ − c));
//! * ∂F_c/∂P̃|_δ = −(b/(2P̃)) q³ + F_q q c/(2P̃ (4q³ − c));
//! * ∂F_c/∂α6 = q² δ̇ (q does not move with α6);
//! * ∂F_c/∂α5 = −∂F_c/∂δ = −F_q/(4q³ − c) (V_T = W + α2 sin Ωτ + α5, eq. 8).
//!
//! Unlike DMT's √δ δ̇, JKR's damper has no singular derivative where the contact forms: there
//! q = c^{1/3} > 0 and dq/dδ = 1/(3c).
//!
//! Beyond the break (δ ≤ δ_b, where an integrator's stage may look across the guard) the law
//! holds q at q_b ([`crate::contact::Jkr::radius_variable`]); there q_b moves with c as the
//! break does, ∂q_b/∂p = (q_b/(3c)) ∂c/∂p (q_b ∝ c^{1/3}), and that is the derivative taken.
//!
//! # The guards
//! The free region's guard V_T does not move with α4 or P̃. The contact's is
//! g = |δ_b| − V_T ([`crate::model::CantileverModel::release_distance`]): the contact breaks at
//! δ_b = q_b⁴ − c q_b with q_b = (1 + ε)(c/4)^{1/3} ([`crate::contact::JKR_BREAK_CUT`]), so
//! δ_b = κ c^{4/3} (κ a number) and ∂δ_b/∂c = (4/3) δ_b/c:
//! ∂g/∂α4 = −∂δ_b/∂α4 = (2/3) δ_b/α4 and ∂g/∂P̃ = −∂δ_b/∂P̃ = −(2/3) δ_b/P̃.
//! The contact forms at δ = 0 with the force jumping from 0 to F(c^{1/3}) = −(4/3)P̃, and
//! breaks at δ_b with the force jumping from F(q_b) to 0: the vector field is discontinuous at
//! both switchings, and the saltation of the extended system (S = I + w ∇gᵀ with these
//! parameter entries of ∇g; Leine & Nijmeijer 2004, §7.1) carries the columns across them.

use super::orbit_param::OrbitParam;
use crate::contact::Jkr;
use crate::system::Region;

/// ∂F_c/∂p of the JKR law (Hertz group α4 = `alpha4`, adhesion P̃ = `adhesion`, Kelvin–Voigt
/// group α6 = `damping`) at indentation δ = `delta` and rate δ̇ = `rate`, in or out of contact
/// (module docs), for p = α5, α4, P̃ and α6; `None` for the other parameters (H̃ is not JKR's;
/// the drive's columns are formed by the extended system from the law's partials).
pub(crate) fn d_force(
    alpha4: f64,
    adhesion: f64,
    damping: f64,
    param: OrbitParam,
    contact: bool,
    delta: f64,
    rate: f64,
) -> Option<f64> {
    let dc_of = |c: f64| match param {
        OrbitParam::ContactStiffness => Some(-c / (2.0 * alpha4)),
        OrbitParam::Adhesion => Some(c / (2.0 * adhesion)),
        _ => None,
    };
    if !matches!(
        param,
        OrbitParam::Gap | OrbitParam::ContactStiffness | OrbitParam::Adhesion | OrbitParam::Damping
    ) {
        return None;
    }
    if !contact {
        return Some(0.0);
    }
    let j = Jkr::new(alpha4, adhesion);
    let q = j.radius_variable(delta);
    if param == OrbitParam::Damping {
        return Some(q * q * rate);
    }
    let (_, f_el) = j.elastic(q);
    // ∂F/∂q at fixed δ̇, the damper's 2α6 q δ̇ with the elastic–adhesive part's
    let f_q = f_el + 2.0 * damping * q * rate;
    let q3 = q * q * q;
    let beyond = delta <= j.release();
    if param == OrbitParam::Gap {
        // the law's own d_delta: 0 beyond the break, where q is held at q_b
        return Some(if beyond { 0.0 } else { -f_q / (4.0 * q3 - j.c) });
    }
    let dc = dc_of(j.c)?;
    // ∂F/∂p at fixed q: F = α4 q⁶ − b q³
    let direct = match param {
        OrbitParam::ContactStiffness => q3 * q3 - j.b / (2.0 * alpha4) * q3,
        _ => -j.b / (2.0 * adhesion) * q3,
    };
    // q moves at fixed δ (on the branch) or with the break (beyond it)
    let dq = if beyond {
        q / (3.0 * j.c) * dc
    } else {
        q * dc / (4.0 * q3 - j.c)
    };
    Some(direct + f_q * dq)
}

/// ∂g/∂p of the guard of `mode` (module docs, *The guards*) for p = α4 and P̃ under JKR
/// (Hertz group α4 = `alpha4`, adhesion P̃ = `adhesion`): 0 in free flight,
/// (2/3)δ_b/α4 and −(2/3)δ_b/P̃ in contact; `None` for the other parameters.
pub(crate) fn d_guard(alpha4: f64, adhesion: f64, mode: Region, param: OrbitParam) -> Option<f64> {
    let scale = match param {
        OrbitParam::ContactStiffness => 1.0 / alpha4,
        OrbitParam::Adhesion => -1.0 / adhesion,
        _ => return None,
    };
    if mode != Region::Contact {
        return Some(0.0);
    }
    let delta_b = Jkr::new(alpha4, adhesion).release();
    Some(2.0 / 3.0 * delta_b * scale)
}

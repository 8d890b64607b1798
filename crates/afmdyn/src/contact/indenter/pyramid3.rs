//! A three-sided pyramid of face inclination α: F = 0.8887 E* tan α δ² (Bilodeau, *J. Appl.
//! Mech.* 59 (1992) 519; the coefficient of nanite 4.2's `hertz_pyr3s`, whose code uses 0.8887
//! where its docstring prints 0.887).

use super::Elastic;

/// Bilodeau's coefficient of the three-sided pyramid, as nanite's `hertz_pyr3s` computes it.
pub(crate) const COEFFICIENT: f64 = 0.8887;

/// g = F/E* = 0.8887 tan α δ² and ∂g/∂δ, at δ > 0 (m) and α = `face_angle` (degrees).
pub(crate) fn elastic(face_angle: f64, delta: f64) -> Elastic {
    let k = COEFFICIENT * face_angle.to_radians().tan();
    Elastic {
        force: k * delta * delta,
        d_delta: 2.0 * k * delta,
        d_radius: 0.0,
    }
}

//! A four-sided (square) pyramid of half angle α between its axis and a face:
//! F = (tan α/√2) E* δ² (Bilodeau, *J. Appl. Mech.* 59 (1992) 519). nanite 4.2 has no
//! four-sided model (no `hertz_pyr4s`): this is the form of the AFM analysis codes that do
//! (e.g. the `pyramid` geometry of the Python `get_coeff` of force-curve rheology scripts).

use super::Elastic;

/// g = F/E* = tan α δ²/√2 and ∂g/∂δ, at δ > 0 (m) and α = `half_angle` (degrees).
pub(crate) fn elastic(half_angle: f64, delta: f64) -> Elastic {
    let k = half_angle.to_radians().tan() * std::f64::consts::FRAC_1_SQRT_2;
    Elastic {
        force: k * delta * delta,
        d_delta: 2.0 * k * delta,
        d_radius: 0.0,
    }
}

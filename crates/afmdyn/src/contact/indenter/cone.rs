//! Sneddon's cone of half-opening angle θ: F = (2/π) E* tan θ δ² (Love 1939; Sneddon, *Int. J.
//! Eng. Sci.* 3 (1965) 47, eq. 6.4; nanite's `hertz_cone`).

use super::Elastic;

/// g = F/E* = (2/π) tan θ δ² and ∂g/∂δ, at δ > 0 (m) and θ = `half_angle` (degrees).
pub(crate) fn elastic(half_angle: f64, delta: f64) -> Elastic {
    let k = 2.0 / std::f64::consts::PI * half_angle.to_radians().tan();
    Elastic {
        force: k * delta * delta,
        d_delta: 2.0 * k * delta,
        d_radius: 0.0,
    }
}

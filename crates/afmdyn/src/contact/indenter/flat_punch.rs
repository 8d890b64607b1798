//! A flat cylindrical punch of radius a: F = 2 E* a δ (Boussinesq 1885; Sneddon, *Int. J. Eng.
//! Sci.* 3 (1965) 47, §6: the contact radius is the punch's at every depth).

use super::Elastic;

/// g = F/E* = 2aδ, ∂g/∂δ = 2a, ∂g/∂a = 2δ, at δ > 0 (m) and a = `radius` (m).
pub(crate) fn elastic(radius: f64, delta: f64) -> Elastic {
    Elastic {
        force: 2.0 * radius * delta,
        d_delta: 2.0 * radius,
        d_radius: 2.0 * delta,
    }
}

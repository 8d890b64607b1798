//! Hertz's paraboloid of apex radius R: F = (4/3) E* √R δ^{3/2} (Hertz 1882; Sneddon, *Int. J.
//! Eng. Sci.* 3 (1965) 47, eq. 6.9; nanite's `hertz_para`).

use super::Elastic;

/// g = F/E* = (4/3)√R δ^{3/2}, ∂g/∂δ = 2√(Rδ), ∂g/∂R = g/(2R), at δ > 0 (m) and R (m).
pub(crate) fn elastic(radius: f64, delta: f64) -> Elastic {
    let s = radius.sqrt();
    let force = 4.0 / 3.0 * s * delta * delta.sqrt();
    Elastic {
        force,
        d_delta: 2.0 * s * delta.sqrt(),
        d_radius: force / (2.0 * radius),
    }
}

//! The free response and the closed forms of the AFM literature (module docs of
//! [`super`]): the free amplitude and lag at Ω, and the equivalent point mass of a mode.

use super::*;

/// The free linear response of the tip at the drive frequency Ω, from the model's complex
/// amplitude H ([`CantileverModel::free_tip_response`], W(1,τ) = Im(H e^{i(Ωτ + ψ)})):
/// A₀ = |H|, lag φ₀ = −arg H. The one place the free amplitude of the closed forms comes from.
///
/// # Errors
/// [`SimError::OutOfRange`] when Ω is at an undamped natural frequency (no steady state).
pub(crate) fn free_response(model: &CantileverModel) -> Result<FreeResponse, SimError> {
    let h = model.free_tip_response()?;
    Ok(FreeResponse {
        amplitude: h.norm(),
        phase: wrap_phase(-h.arg()),
    })
}

/// The closed forms of `model` for a first-harmonic tip amplitude `a` (g₀) and lag `phase`
/// (rad) (see [`ClosedForms`]; k̃, Q, ω₀ and A₀ depend on the model only).
///
/// # Errors
/// As [`free_response`].
pub(crate) fn closed_forms(
    model: &CantileverModel,
    a: f64,
    phase: f64,
) -> Result<ClosedForms, SimError> {
    let free = free_response(model)?;
    let m = EquivalentMode::of(model, 0);
    let (k, q) = (m.stiffness, m.quality_factor);
    let r = model.omega() / m.natural_frequency;
    let a0 = free.amplitude;
    Ok(ClosedForms {
        free_amplitude: a0,
        free_phase: free.phase,
        quality_factor: q,
        natural_frequency: m.natural_frequency,
        stiffness: k,
        drive_force: k * a0 * ((1.0 - r * r).powi(2) + (r / q).powi(2)).sqrt(),
        energy_dissipated: m.energy_dissipated(a, a0, phase, model.omega()),
        virial: m.virial(a, a0, phase),
    })
}

/// The equivalent point mass of one mode at the tip: ω₀, k̃ ([`crate::eigen::mode_at_tip`]) and
/// Q = 1/(2ζ) of its damped eigenvalue — what the closed forms of the AFM literature take.
pub(super) struct EquivalentMode {
    natural_frequency: f64,
    stiffness: f64,
    quality_factor: f64,
}

impl EquivalentMode {
    /// Mode `mode` (0-based) of `model`; Q from the mode-th underdamped eigenvalue (for mode 1
    /// the first eigenvalue when none is underdamped; ∞ without one).
    pub(super) fn of(model: &CantileverModel, mode: usize) -> Self {
        let g = model.galerkin().region(Region::Free);
        let (w0, _, k) = crate::eigen::mode_at_tip(g, model.tip(), mode);
        let eig = damped_eigenvalues(g);
        let under = eig.iter().filter(|e| e.im > 0.0).nth(mode);
        let e = if mode == 0 {
            under.or(eig.first())
        } else {
            under
        };
        EquivalentMode {
            natural_frequency: w0,
            stiffness: k,
            quality_factor: e.map_or(f64::INFINITY, |e| 0.5 / e.zeta),
        }
    }

    /// Cleveland/Anczykowski E_cf = (π k A²/Q)[(A₀/A) sin φ − ω/ω₀] per cycle at frequency ω
    /// (module docs).
    pub(super) fn energy_dissipated(&self, a: f64, a0: f64, phase: f64, omega: f64) -> f64 {
        let r = omega / self.natural_frequency;
        PI * self.stiffness / self.quality_factor * (a * a0 * phase.sin() - r * a * a)
    }

    /// San Paulo & García V_cf = −(k A A₀/(2Q)) cos φ (module docs).
    pub(super) fn virial(&self, a: f64, a0: f64, phase: f64) -> f64 {
        -self.stiffness * a * a0 / (2.0 * self.quality_factor) * phase.cos()
    }
}

//! The model parameters whose exact orbit sensitivities are taken ([`super::sensitivity`];
//! the JKR law's derivatives in [`super::sensitivity_jkr`]): named once here, below both.

use serde::Serialize;

/// A model parameter whose sensitivity is taken (dimensionless, the model's).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub(crate) enum OrbitParam {
    /// α5, the gap: V_T = W + α2 sin Ωτ + α5 (eq. 8); a rest distance z_c moves it one to one.
    Gap,
    /// α4, the Hertz group of the Hertz and DMT laws (∝ E* √R).
    ContactStiffness,
    /// α6, the contact's damper: the Hertz law's (F_c = α4 δ^{3/2} + α6 δ̇ in contact; ∝ the
    /// probe's `[sample] damping`, N s/m) or DMT's Kelvin–Voigt term (α6 √δ δ̇; ∝ the probe's
    /// `[sample] viscosity` η √R, Pa s).
    Damping,
    /// H̃, DMT's van der Waals group (∝ H R).
    Hamaker,
    /// α2, the drive's amplitude (the base's, or the tip force's of the point mass): it enters
    /// the forcing linearly and, on the base-driven beam, the gap V_T (eq. 8).
    DriveAmplitude,
    /// Ω, the drive's frequency, with the period T = 2π/Ω moving with it (the orbit's
    /// sensitivity at a fixed phase Ωτ; module docs, *The drive*).
    DriveFrequency,
    /// α3, the lever's damping (C^I = α3 diag(s), eq. 12; α3 ∝ 1/Q₁): it enters the rate
    /// through −M⁻¹ diag(s) ȧ and, on the base-driven beam, the forcing's base-velocity term
    /// (eq. 14) (module docs, *The lever's damping*).
    LeverDamping,
    /// F̃₁, the force of the drive's first further component (a bimodal drive's second, a tip
    /// force F̃₁ cos(ω₁τ + θ₁), [`crate::params::Params::drive_components`]): its column is
    /// M⁻¹φ cos(ω₁τ + θ₁).
    ComponentForce,
    /// P̃, the JKR law's adhesion group (πWR/F̃-unit, ∝ W R; [`crate::contact::Jkr`]).
    Adhesion,
}

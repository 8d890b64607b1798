//! Maps as a layer: derived discrete-time systems over any [`Integrator`] (as the derived
//! systems of DynamicalSystemsBase.jl), on which the analyses work instead of on the flow.
//!
//! The one map here is the period-n stroboscopic Poincaré map P(z) = z(nT) from drive phase 0,
//! T = 2π/Ω the drive period in the dimensionless time τ of eq. 5 ([`StroboscopicMap`]). Its
//! state is `z: [f64; 2N]` = (a, ȧ), the modal coordinates and their τ-derivatives; with it
//! come, on request, the monodromy matrix ∂P/∂z (2N×2N, with the saltation matrices of the
//! events), the parameter derivative ∂P/∂p (`[2N]`) and the distance to grazing
//! ([`flow::FlowMap`]). Errors are the integrator's [`SimError`]s.
//!
//! - `discrete`: the trait [`DiscreteMap`] (image, Jacobian, parameter derivative, distance
//!   to grazing of the n-th iterate), which the map-only analyses take;
//! - [`flow`]: the flow map z(τ0) ↦ z(τ1) of any integrator with its Jacobian (step Jacobians
//!   times saltation matrices), its parameter derivative and the distance to grazing — the one
//!   loop every map and the Lyapunov spectrum use;
//! - `circle`: `circle::CircleMap`, the invariant circle of a two-frequency drive's
//!   stroboscopic map as the fixed point of a map (quasi-periodic steady states);
//! - `stroboscopic`: [`StroboscopicMap`], the value the analyses iterate: steady states and
//!   period detection ([`crate::analysis::steady`], [`crate::analysis::settle`]), Newton
//!   shooting and Floquet multipliers ([`crate::analysis::shooting`]), continuation
//!   ([`crate::analysis::continuation`]) and the stepped curves' fixed-point checks.
//!
//! [`Integrator`]: crate::integrate::Integrator
//! [`SimError`]: crate::error::SimError

pub(crate) mod circle;
pub(crate) mod discrete;
pub mod flow;
pub(crate) mod stroboscopic;

pub use discrete::DiscreteMap;
pub use stroboscopic::StroboscopicMap;

//! The map as a trait: [`DiscreteMap`], a discrete-time system z ↦ P(z) with its Jacobian, on
//! which the analyses that need only the map are written (Newton shooting and Floquet
//! multipliers, [`crate::analysis::shooting`]; the minimal period of a settled orbit,
//! [`crate::analysis::settle::minimal_period`]). As DynamicalSystemsBase.jl's derived systems
//! (Datseris, *J. Open Source Softw.* 3 (2018) 598), any system that gives a map can be
//! analysed, and one conformance suite (`tests/maps.rs`) runs every implementation through the
//! same code: [`crate::maps::StroboscopicMap`] over any integrator, and a test's affine map.

use crate::error::SimError;
use crate::maps::flow::FlowMap;
use nalgebra::DVector;

/// A discrete-time map P on states `z: [f64; d]` (d = [`DiscreteMap::dim`]), asked for its
/// n-th iterate Pⁿ(z) as one operation — an implementation may compute Pⁿ better than by
/// composing n images (the stroboscopic map integrates one flow over n drive periods).
///
/// Every call starts afresh from the given state: the map keeps no trajectory. Errors are the
/// implementation's [`SimError`]s ([`SimError::Cancelled`] is passed on by every analysis).
pub trait DiscreteMap {
    /// The state dimension d (2N for the cantilever's modal state (a, ȧ)).
    fn dim(&self) -> usize;

    /// The number of drive periods one iterate spans (1 for a map that is not stroboscopic).
    fn periods(&self) -> usize;

    /// The duration of one iterate, in the map's time unit (dimensionless τ for the
    /// stroboscopic map: [`DiscreteMap::periods`] × 2π/Ω; 1 for a map that has no time).
    fn duration(&self) -> f64;

    /// Pⁿ(z) alone, n ≥ 1, `[d]`: no Jacobian (for the stroboscopic map, a flow without the
    /// variational equations).
    ///
    /// # Errors
    /// The implementation's (a diverging or failing iterate).
    fn iterate(&mut self, z: &DVector<f64>, n: usize) -> Result<DVector<f64>, SimError>;

    /// Pⁿ(z), n ≥ 1, with its Jacobian ∂Pⁿ/∂z (d×d: for the stroboscopic map the monodromy
    /// matrix, saltation matrices included), the parameter derivative ∂Pⁿ/∂p where the map
    /// provides it ([`FlowMap::param_derivative`], else `None`) and, when `grazing`, the
    /// distance to grazing ([`FlowMap::grazing_distance`], else NaN), in a [`FlowMap`]. A map
    /// without events reports 0 switchings and contacts, a contact time of 0 and an infinite
    /// distance to grazing.
    ///
    /// # Errors
    /// The implementation's; [`SimError::Unsupported`] where the Jacobian is not available.
    fn linearise(&mut self, z: &DVector<f64>, n: usize, grazing: bool)
        -> Result<FlowMap, SimError>;

    /// The distance to grazing of Pⁿ(z) ([`FlowMap::grazing_distance`]): how close the motion
    /// from z comes to a switching surface. Default: +∞, a map without switchings.
    ///
    /// # Errors
    /// The implementation's.
    fn grazing_distance(&mut self, z: &DVector<f64>, n: usize) -> Result<f64, SimError> {
        let _ = (z, n);
        Ok(f64::INFINITY)
    }

    /// Check a state the map is to start from, named `name` in the error. Default:
    /// `crate::system::check_state` (length d, finite entries, ‖z‖ ≤ 1e12).
    ///
    /// # Errors
    /// [`SimError::StateLength`], [`SimError::NotFinite`] or [`SimError::OutOfRange`].
    fn check_state(&self, name: &'static str, z: &DVector<f64>) -> Result<(), SimError> {
        crate::system::check_state(name, self.dim(), z)
    }

    /// Whether a fixed point z = Pⁿ(z) is a periodic orbit of the system the map comes from.
    /// For a hybrid system with hysteresis the map restarts at z in the region its rule gives,
    /// which need not be the one the motion ends in ([`crate::analysis::shooting`] refuses such
    /// points). Default: `true`.
    ///
    /// # Errors
    /// The implementation's.
    fn closes(&mut self, z: &DVector<f64>, n: usize) -> Result<bool, SimError> {
        let _ = (z, n);
        Ok(true)
    }
}

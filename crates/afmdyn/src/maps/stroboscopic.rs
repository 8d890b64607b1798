//! The period-n stroboscopic map P(z) = z(nT) of any [`Integrator`], from drive phase 0
//! (τ = 0 → nT, T = 2π/Ω in the dimensionless τ of eq. 5), with its monodromy matrix (the
//! product of the step Jacobians and of the saltation matrices of the events, Leine & Nijmeijer
//! 2004, ch. 7), the parameter derivative ∂P/∂p and the distance to grazing on request
//! ([`crate::maps::flow`] computes the flows).

use crate::error::SimError;
use crate::integrate::{build, Integrator, IntegratorOptions};
use crate::maps::discrete::DiscreteMap;
use crate::maps::flow::{flow, flow_state, grazing_distance, FlowMap};
use crate::model::CantileverModel;
use crate::params::SweepParam;
use nalgebra::DVector;

/// The period-n stroboscopic map over an integrator: a value built with [`StroboscopicMap::new`]
/// (Jacobian on, grazing watched, no parameter derivative) and its options, then applied to
/// states `z: [f64; 2N]` = (a, ȧ).
///
/// * `StroboscopicMap::apply`: Pⁿ(z) with the monodromy matrix ∂Pⁿ/∂z (2N×2N) and, as
///   asked for, ∂Pⁿ/∂p (`StroboscopicMap::with_param_derivative`) and the distance to grazing
///   ([`StroboscopicMap::watch_grazing`]), in a [`FlowMap`];
/// * [`StroboscopicMap::image`]: Pⁿ(z) alone, the Jacobian off (variational equations off);
/// * [`StroboscopicMap::grazing_distance`]: the distance to grazing alone.
///
/// Every call restarts the integrator at τ = 0 from the given state. The integrator is the
/// caller's ([`StroboscopicMap::new`]) or the map's own (`StroboscopicMap::build`).
pub struct StroboscopicMap<'a> {
    integ: Held<'a>,
    periods: usize,
    param: Option<SweepParam>,
    grazing: bool,
}

/// The integrator a map runs on: the caller's, or the map's own.
enum Held<'a> {
    Borrowed(&'a mut dyn Integrator),
    Owned(Box<dyn Integrator>),
}

impl StroboscopicMap<'static> {
    /// The period-`periods` map over its own integrator of `model`, built at (τ = 0, `z`) with
    /// `opts` ([`crate::integrate::build`]): the set-up of an analysis that shoots or iterates
    /// from `z` on the model ([`StroboscopicMap::integrator`] hands the integrator out).
    ///
    /// # Errors
    /// As [`crate::integrate::build`].
    pub(crate) fn build(
        model: &CantileverModel,
        opts: IntegratorOptions,
        z: &DVector<f64>,
        periods: usize,
    ) -> Result<Self, SimError> {
        Ok(Self::held(
            Held::Owned(build(model, opts, 0.0, z)?),
            periods,
        ))
    }
}

impl<'a> StroboscopicMap<'a> {
    /// The period-`periods` map (n ≥ 1 drive periods) over `integ` at its system's parameters:
    /// Jacobian on, distance to grazing watched, no parameter derivative.
    pub fn new(integ: &'a mut dyn Integrator, periods: usize) -> Self {
        Self::held(Held::Borrowed(integ), periods)
    }

    fn held(integ: Held<'a>, periods: usize) -> Self {
        StroboscopicMap {
            integ,
            periods,
            param: None,
            grazing: true,
        }
    }

    /// Watch the distance to grazing ([`FlowMap::grazing_distance`]) in `Self::apply` (the
    /// default) or not (then NaN): the iterates of a Newton solve need the state and the
    /// monodromy matrix only, and the converged point takes [`Self::grazing_distance`] once
    /// (the local-extremum searches of V_T are a sixth of a period-1 shooting solve at N = 3).
    #[must_use]
    pub fn watch_grazing(mut self, on: bool) -> Self {
        self.grazing = on;
        self
    }

    /// Ask [`Self::apply`] for ∂Pⁿ/∂p at fixed z ([`FlowMap::param_derivative`], `[2N]`): the
    /// parameter sensitivity along the flow (variational equation of the parameter, Hairer,
    /// Nørsett & Wanner, *Solving ODEs I*, §I.14, with the saltation's shift at each event), and
    /// for p = Ω the moving end time nT = 2πn/Ω, which adds ż(nT) d(nT)/dΩ = −ż(nT) nT/Ω.
    /// `None` there when the integrator or the law does not provide it.
    #[must_use]
    pub(crate) fn with_param_derivative(mut self, param: SweepParam) -> Self {
        self.param = Some(param);
        self
    }

    /// The number n of drive periods per iterate.
    pub fn periods(&self) -> usize {
        self.periods
    }

    /// The duration nT of one iterate (dimensionless τ).
    pub(crate) fn duration(&self) -> f64 {
        self.duration_of(self.periods)
    }

    /// The integrator the map runs on (its state after a call is the last image's).
    pub fn integrator(&mut self) -> &mut dyn Integrator {
        match &mut self.integ {
            Held::Borrowed(i) => &mut **i,
            Held::Owned(i) => i.as_mut(),
        }
    }

    /// The integrator, read only.
    fn integ(&self) -> &dyn Integrator {
        match &self.integ {
            Held::Borrowed(i) => &**i,
            Held::Owned(i) => i.as_ref(),
        }
    }

    /// Pⁿ(z) with its monodromy matrix, and ∂Pⁿ/∂p and the distance to grazing as asked for.
    /// Switches the integrator's variational equations on.
    ///
    /// # Errors
    /// [`SimError`] from the integrator, [`SimError::Unsupported`] for one without step
    /// Jacobians.
    pub(crate) fn apply(&mut self, z: &DVector<f64>) -> Result<FlowMap, SimError> {
        self.apply_over(z, self.periods, self.grazing)
    }

    /// The duration of `periods` drive periods (dimensionless τ).
    fn duration_of(&self, periods: usize) -> f64 {
        periods as f64 * self.integ().system().period()
    }

    /// [`Self::apply`] over `periods` drive periods, the distance to grazing when `grazing`.
    fn apply_over(
        &mut self,
        z: &DVector<f64>,
        periods: usize,
        grazing: bool,
    ) -> Result<FlowMap, SimError> {
        let (t, param) = (self.duration_of(periods), self.param);
        let mut map = flow(self.integrator(), 0.0, z, t, param, grazing)?;
        if let (Some(d), Some(SweepParam::Omega)) = (&mut map.param_derivative, param) {
            let mut f = DVector::zeros(z.len());
            let m = self.integ().system();
            m.rhs(
                self.integ().region(),
                t,
                map.state.as_slice(),
                f.as_mut_slice(),
            );
            d.axpy(-t / m.omega(), &f, 1.0);
        }
        Ok(map)
    }

    /// Pⁿ(z) alone, with the variational equations switched off (an integrator whose step
    /// control sees them — the adaptive one — then takes its own steps, a seventh of the work
    /// of a variational step at N = 3): for finite differences of the map, whose flows must all
    /// take steps chosen alike, not for the `state` of `Self::apply`.
    ///
    /// # Errors
    /// [`SimError`] from the integrator.
    pub fn image(&mut self, z: &DVector<f64>) -> Result<DVector<f64>, SimError> {
        let t = self.duration();
        flow_state(self.integrator(), 0.0, z, t)
    }

    /// The distance to grazing of Pⁿ(z) ([`FlowMap::grazing_distance`]) without the Jacobian:
    /// the same steps and searches as a watched `Self::apply`, so the same value.
    ///
    /// # Errors
    /// [`SimError`] from the integrator.
    pub fn grazing_distance(&mut self, z: &DVector<f64>) -> Result<f64, SimError> {
        let t = self.duration();
        grazing_distance(self.integrator(), 0.0, z, t)
    }
}

/// The period-n map as a [`DiscreteMap`]: one iterate spans [`StroboscopicMap::periods`] drive
/// periods, and Pᵏ is one flow over k·n periods (the same flow as the inherent methods of a map
/// of k·n periods, so the same numbers); the parameter derivative as set by
/// `StroboscopicMap::with_param_derivative`.
impl DiscreteMap for StroboscopicMap<'_> {
    fn dim(&self) -> usize {
        self.integ().system().dim()
    }

    fn periods(&self) -> usize {
        self.periods
    }

    fn duration(&self) -> f64 {
        StroboscopicMap::duration(self)
    }

    fn iterate(&mut self, z: &DVector<f64>, n: usize) -> Result<DVector<f64>, SimError> {
        let t = self.duration_of(self.periods * n);
        flow_state(self.integrator(), 0.0, z, t)
    }

    fn linearise(
        &mut self,
        z: &DVector<f64>,
        n: usize,
        grazing: bool,
    ) -> Result<FlowMap, SimError> {
        self.apply_over(z, self.periods * n, grazing)
    }

    fn grazing_distance(&mut self, z: &DVector<f64>, n: usize) -> Result<f64, SimError> {
        let t = self.duration_of(self.periods * n);
        grazing_distance(self.integrator(), 0.0, z, t)
    }

    fn check_state(&self, name: &'static str, z: &DVector<f64>) -> Result<(), SimError> {
        self.integ().system().check_state(name, z)
    }

    /// For a hysteretic system ([`crate::tip_sample::TipSampleSystem::is_hysteretic`]): whether
    /// the flow from z ends in the region a start at z is given
    /// ([`crate::system::HybridSystem::mode_at`]'s rule in the neck's band): one extra flow,
    /// for such systems only; `true` for every other system.
    fn closes(&mut self, z: &DVector<f64>, n: usize) -> Result<bool, SimError> {
        if !self.integ().system().is_hysteretic() {
            return Ok(true);
        }
        let start = self.integ().system().mode_at(0.0, z.as_slice());
        self.iterate(z, n)?;
        Ok(self.integ().region() == start)
    }
}

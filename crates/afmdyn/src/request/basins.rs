//! `basins`: the request of a basin map ([`crate::analysis::basins`]) that the command line
//! and Python share — its options with their limits and the worker threads (its document and
//! arrays, [`BasinArrays`], are `crate::report::basins`'s), its checks ([`BasinsRequest::spec`])
//! and its declared cost. It runs as a study of rows, pass by pass, in the study layer.

use super::analyses::{initial_state, IntegratorRequest, SteadyRequest};
use super::costs::basins_cost;
use crate::analysis::basins::{
    BasinSpec, StateCoord, DEFAULT_BASIN_HITS, DEFAULT_CELL, DEFAULT_DISCOVER_AFTER,
    DEFAULT_NEAR_TOL, DEFAULT_STRIDE,
};
use crate::analysis::bifurcation::SweepSpec;
use crate::error::SimError;
use crate::model::CantileverModel;
use crate::params::Params;
pub use crate::report::basins::BasinArrays;

request! {
    /// `basins`: a basin map over two coordinates of the initial state at τ = 0.
    pub struct BasinsRequest {
        /// x coordinate: `a1`…`aN`, `adot1`…`adotN`, `w` or `wdot` (the tip, set through mode 1).
        pub x: String = "a1".into(),
        /// First x value (g0, or g0 per unit τ for a velocity).
        pub x_from: f64 = -0.6,
        /// Last x value.
        pub x_to: f64 = 0.6,
        /// Number of x values (columns).
        pub x_steps: usize = 40,
        /// y coordinate, as `x`.
        pub y: String = "adot1".into(),
        /// First y value.
        pub y_from: f64 = -1.2,
        /// Last y value.
        pub y_to: f64 = 1.2,
        /// Number of y values (rows).
        pub y_steps: usize = 40,
        /// The other coordinates of every start, 2N values (a1…aN, ȧ1…ȧN); `None`: the rest state.
        pub base: Option<Vec<f64>>,
        /// Relative distance to a periodic attractor's section point that counts as near, (0, 1].
        pub near_tol: f64 = DEFAULT_NEAR_TOL,
        /// Side of the state-space cells of the recurrence test (g0; ×Ω for velocities), > 0.
        pub cell: f64 = DEFAULT_CELL,
        /// Consecutive returns in cells of one basin that decide a start (0: no recurrence test).
        pub basin_hits: usize = DEFAULT_BASIN_HITS,
        /// Returns tested before the steady-state search takes over.
        pub discover_after: usize = DEFAULT_DISCOVER_AFTER,
        /// Stride of the first pass's coarse grid (0: automatic, 1: one pass).
        pub stride: usize = DEFAULT_STRIDE,
        /// Relative tolerance for two steady states to be one attractor, > 0.
        pub cluster_tol: f64 = super::DEFAULT_CLUSTER_TOL,
        /// Worker threads, 1..=[`MAX_THREADS`](super::limits::MAX_THREADS); `None`: all cores.
        constants(MAX_THREADS in super::limits)
        pub threads: Option<usize>;
        flatten steady: SteadyRequest, integrator: IntegratorRequest,
    }
}

fn coord(name: &'static str, s: &str) -> Result<StateCoord, SimError> {
    s.parse()
        .map_err(|_| SimError::out_of_range(name, s, "must be a1…aN, adot1…adotN, w or wdot"))
}

impl BasinsRequest {
    /// The validated map of `params` ([`BasinSpec::validate`], the coordinates within the N
    /// modes, the base state's length and entries, the thread count).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming the option; [`SimError::StateLength`] for a base of
    /// another length than 2N; [`SimError::Params`] for invalid parameters.
    pub fn spec(&self, params: &Params) -> Result<BasinSpec, SimError> {
        super::limits::check_threads(self.threads)?;
        let (x, y) = (coord("x", &self.x)?, coord("y", &self.y)?);
        let model = CantileverModel::new(params)?;
        let spec = BasinSpec {
            params: *params,
            x,
            xs: SweepSpec::linspace(self.x_from, self.x_to, self.x_steps)
                .map_err(|e| rename(e, ["x_from", "x_to", "x_steps"]))?,
            y,
            ys: SweepSpec::linspace(self.y_from, self.y_to, self.y_steps)
                .map_err(|e| rename(e, ["y_from", "y_to", "y_steps"]))?,
            base: initial_state(&model, self.base.as_deref()).map_err(|e| match e {
                SimError::StateLength { expected, got, .. } => SimError::StateLength {
                    name: "base (a1..aN, adot1..adotN)",
                    expected,
                    got,
                },
                SimError::OutOfRange { value, allowed, .. } => SimError::OutOfRange {
                    name: "base",
                    value,
                    allowed,
                },
                e => e,
            })?,
            near_tol: self.near_tol,
            cell: self.cell,
            basin_hits: self.basin_hits,
            discover_after: self.discover_after,
            stride: self.stride,
            steady: self.steady.options()?,
            cluster_tol: self.cluster_tol,
            integrator: self.integrator.options(1)?,
        };
        spec.validate()?;
        Ok(spec)
    }
}

/// An error of [`SweepSpec::linspace`] named after the axis' option (`from`, `to`, `steps`).
fn rename(e: SimError, [from, to, steps]: [&'static str; 3]) -> SimError {
    match e {
        SimError::OutOfRange {
            name,
            value,
            allowed,
        } => SimError::OutOfRange {
            name: match name {
                "from" => from,
                "to" => to,
                "steps" => steps,
                other => other,
            },
            value,
            allowed,
        },
        SimError::NotFinite { name, value } => SimError::NotFinite {
            name: if name == "from" { from } else { to },
            value,
        },
        e => e,
    }
}

impl_request! {
    BasinsRequest, "basins",
    advice = "ask for fewer cells (x_steps × y_steps) or a shorter transient (max_periods)";
    validate |r, model| r.spec(&model.params).map(|_| ());
    cost |r, model| basins_cost(&r.spec(&model.params)?)
}

//! Exact propagation of the piecewise-linear model with located switchings.
//!
//! Between switchings each region is linear and time-invariant with constant plus harmonic
//! forcing (eq. 10), so with δz = z − z_p(τ) (z_p the periodic particular solution)
//!
//! z(τ + t) = z_p(τ + t) + e^{A_s t} δz(τ).
//!
//! **Grid.** The drive period T is split into m sub-steps h = T/m with ‖Ã_s‖₂ h ≤ θ, where
//! Ã_s = T_s A_s T_s⁻¹ is A_s in energy coordinates y = (L_Kᵀ a, L_Mᵀ ȧ) (K_s = L_K L_Kᵀ,
//! M = L_M L_Mᵀ). Φ_s = e^{A_s h} and z_p at the grid points are precomputed, so a dense step
//! costs one 2N×2N matrix–vector product (`linalg/kernel.rs`: fixed-size for N ≤ 6). Partial steps
//! (after a switching, to a requested time) use the eigendecomposition of Ã (`exact/modal.rs`)
//! when it is well conditioned, else the Taylor series of e^{Ã t} y, which converges fast because
//! ‖Ã t‖ ≤ θ.
//!
//! **Modal propagation** ([`Propagation`]). A region whose eigenvector basis is well conditioned
//! (at any N) keeps the homogeneous part in modal coordinates q = V⁻¹ T δz during a stint: a grid
//! step multiplies q by e^{Λh} (about N complex products) and evaluates the tip from q; the
//! plain state z = z_p + T⁻¹ V q is formed only when asked for ([`Integrator::step`] returns it
//! after every step, [`Spans::advance_to`] only at events and at the end). The
//! eigendecomposition also tightens the curvature bound below.
//!
//! **Switching detection** on the gap g = ±V_T (eq. 8; + in region I, − in region II) is rigorous:
//! in energy coordinates the homogeneous flow does not increase ‖y‖ (Ã + Ãᵀ ⪯ 0 since C ⪰ 0),
//! so |g''| ≤ ‖Ãᵀ² c̃‖ ‖y(τ_entry)‖ + Ω²|V_p| bounds the curvature over the stint. A step is
//! accepted without search when g(a) + min(g'(a), 0) len − B len²/2 > 0 (the lower parabola from
//! a stays positive: most steps away from the sample, with no square root), or when the two
//! parabolas g(a) + g'(a)s − Bs²/2 and g(b) − g'(b)s − Bs²/2 prove g > 0 over it; otherwise the
//! tip motion in the step is expanded as a power series (moments c̃ᵀÃⁿy), the bound is
//! tightened, and a pruned bisection finds the
//! *leftmost* zero — also a dip below V_T = 0 that returns between two grid points (grazing) —
//! which a safeguarded Newton iteration polishes to round-off.
//!
//! **No re-trigger.** Right after a switching g = 0 and g' > 0 in the new region; the search
//! starts where the lower parabola g'(0)s − Bs²/2 is largest, so the same event cannot fire twice.
//! Many switchings in a vanishing time window are reported as [`SimError::Chattering`].
//!
//! **Parts.** `build.rs` (the options, the grid, the cached data), `cache.rs` (the caller's
//! [`PropagatorCache`]), `forcing.rs` (the particular solutions and their grid tables),
//! `state.rs` (the state between steps),
//! `step.rs` (one step and the switching test; the search in `search.rs`), `run.rs` (runs of
//! certified whole grid steps), `series.rs` (the last step, dense output, tip series), `span.rs` (spans of steps),
//! `sensitivity.rs` (step Jacobians and ∂z/∂p), `bound.rs` (the displacement bound),
//! `integrator.rs` (the [`Integrator`] implementation), `noise.rs` (the thermally driven lever's
//! exact stochastic step, [`ThermalExact`]), `spectral.rs` and `modal.rs` (the
//! spectral data of the region matrices, the eigendecomposition), `tip.rs` (V_T of a plain
//! state), `tests.rs`.
//!
//! [`Integrator`]: crate::integrate::Integrator
//! [`Spans::advance_to`]: crate::integrate::Spans::advance_to
//! [`Integrator::step`]: crate::integrate::Integrator::step
//! [`SimError::Chattering`]: crate::error::SimError::Chattering

mod bound;
mod build;
pub(crate) mod cache;
mod energy;
mod forcing;
mod handoff;
mod integrator;
mod modal;
pub mod noise;
mod run;
mod sample;
mod search;
mod sensitivity;
mod series;
mod span;
mod spectral;
mod state;
mod step;
#[cfg(test)]
mod tests;
mod tip;

pub(crate) use crate::linalg::matmul_into;
pub use build::{ExactOptions, Propagation};
pub use cache::PropagatorCache;
pub use noise::{ThermalExact, ThermalForce};

use super::grid::PeriodGrid;
use super::ChatterWindow;
use crate::linalg::kernel::MatVec;
use crate::model::CantileverModel;
use crate::params::SweepParam;
use crate::system::Region;
use bound::BoundCols;
use forcing::Forced;
use modal::{Modes, MAXD};
use nalgebra::{DMatrix, DVector};
use search::TipPoly;
use sensitivity::ParticularDerivative;
use series::LastStep;
use spectral::Spectral;
use std::sync::Arc;

/// Bound on ‖Ã‖₂ h for the grid step (radians of the fastest mode per step).
pub(crate) const THETA: f64 = 4.0;
/// Number of Taylor terms kept in partial steps and tip polynomials (‖Ãt‖ ≤ θ = 4:
/// θ^40/40! ≈ 1.5e-24, below round-off even after the largest term, θ⁴/4! ≈ 11).
const K: usize = 39;
/// The K + 1 terms of a tip series in blocks of four (`build_poly`).
const TERM_BLOCKS: usize = (K + 1) / 4;
const _: () = assert!((K + 1).is_multiple_of(4));
/// Switchings within [`CHATTER_WINDOW`] of τ that count as chattering.
const CHATTER_COUNT: usize = 64;
/// Time window of the chattering test.
const CHATTER_WINDOW: f64 = 1e-9;

/// 1/n!, n = 0..=K + 1.
const INV_FACT: [f64; K + 2] = {
    let mut f = [1.0; K + 2];
    let mut prod = 1.0;
    let mut n = 1;
    while n <= K + 1 {
        prod *= n as f64;
        f[n] = 1.0 / prod;
        n += 1;
    }
    f
};

/// 1/n, n = 0..=K + 2 (entry 0 unused): the series' tail test without a division.
const INV_INT: [f64; K + 3] = {
    let mut f = [0.0; K + 3];
    let mut n = 1;
    while n <= K + 2 {
        f[n] = 1.0 / n as f64;
        n += 1;
    }
    f
};

/// Exact propagator (see the module docs).
#[derive(Debug, Clone)]
pub struct ExactPropagator {
    model: CantileverModel,
    spec: Arc<[Spectral; 2]>,
    /// Φ_s = e^{A_s h} in plain coordinates.
    phi: Arc<[DMatrix<f64>; 2]>,
    /// Forcing-dependent data of both regions (shared by clones).
    forced: Arc<[Forced; 2]>,
    /// Whether each region's grid steps are modal.
    modal: [bool; 2],
    /// Whether the spectral data, the grid exponential and the forcing data came from earlier
    /// builds.
    reused: (bool, bool, bool),
    /// Dense grid-step kernel for this dimension.
    kernel: MatVec,
    grid: PeriodGrid,
    tau: f64,
    z: DVector<f64>,
    /// Modal coordinates of the homogeneous part of the current state (valid in a modal region).
    q: Box<Modes>,
    /// The homogeneous part's tip deflection and rate at q, as the step of `step_impl` that
    /// formed q returned them (`ModalExp::advance_into`, equal bit for bit to
    /// `ModalExp::tip_of(q)`); `None` where q was formed otherwise (a run of grid steps, the
    /// batch, a stint entry).
    tip_hom: Option<(f64, f64)>,
    /// z lags behind q (inside [`Spans::advance_to`]).
    ///
    /// [`Spans::advance_to`]: crate::integrate::Spans::advance_to
    stale: bool,
    /// Modal scratch: e^{λ_k t} of a partial step, the coordinates at the centre of a tip
    /// series, the step tried by a run of grid steps.
    scratch: Box<Modes>,
    region: Region,
    /// The grid point the state is on, as (period p, sub-step k < m): grid index j = p m + k.
    on_grid: Option<(i64, usize)>,
    /// Off the grid, the next grid point and its time, as the last step found it (valid while
    /// τ is before that time; `None` after a reset).
    between: Option<((i64, usize), f64)>,
    /// Bound on |W_hom''| over the current stint (see `enter_stint`).
    stint_curvature: f64,
    just_switched: bool,
    chatter: ChatterWindow,
    last: LastStep,
    /// Tip polynomial of the last step, valid when `poly_built` (filled in place).
    poly: Box<TipPoly>,
    poly_built: bool,
    /// V_T and dV_T/dτ at the current state.
    vt: (f64, f64),
    /// τ of the last switching or reset and (sin Ωτ, cos Ωτ) there (the start of the next step).
    entry_trig: (f64, (f64, f64)),
    /// Round-off dead band of the switching test: a region is left when V_T passes 0 by more
    /// than this (1e-15 of the displacement scale). A tip resting on the sample with zero force
    /// (V_T = V̇_T = 0, e.g. α2 = α5 = 0 from rest) then stays put instead of chattering; a real
    /// switching is located within dead/|dV_T/dτ| ≈ 1e-14 of V_T = 0.
    dead: f64,
    /// sin Ωτ_k and cos Ωτ_k on the grid of one period (k = 0..=m).
    trig: Arc<[(f64, f64)]>,
    /// The same at the middles of the grid steps, τ_k + h/2 (k < m): the centres of the tip
    /// series of whole grid steps.
    trig_mid: Arc<[(f64, f64)]>,
    zb: DVector<f64>,
    /// δz of the step tried by a dense run (the other buffer is the last step's `dz0`).
    dz_run: DVector<f64>,
    /// ∂z_p/∂p of both regions for the last parameter asked for
    /// ([`Integrator::last_step_param_derivative_into`]).
    ///
    /// [`Integrator::last_step_param_derivative_into`]: crate::integrate::Integrator::last_step_param_derivative_into
    param_data: Option<(SweepParam, Arc<[ParticularDerivative; 2]>)>,
    /// ∂z_p/∂p at the end (τ, region) of the last step it was asked for.
    param_end: Option<(f64, Region, [f64; MAXD])>,
    /// The tables of the closed-form energy integrals over grid steps (`energy.rs`), built on
    /// the first request.
    energy: Option<Arc<[energy::EnergyTable; 2]>>,
    /// The column sums of [`Spans::displacement_bound`] for the last weights.
    ///
    /// [`Spans::displacement_bound`]: crate::integrate::Spans::displacement_bound
    bound_cols: BoundCols,
    /// The body-contact guard of the span being taken: the homogeneous part's bound at its
    /// start (`span.rs`, `bound.rs`'s `StepGuard`); `None` outside a span or without a check.
    span_guard: Option<f64>,
    /// Whether the guard ended the span: the last step's end is not shown off the substrate.
    guard_stopped: bool,
    /// The modal coordinates at the start of a span ([`Spans::step_span`], `span.rs`); they
    /// trade places with the last step's start when the span becomes the last step.
    ///
    /// [`Spans::step_span`]: crate::integrate::Spans::step_span
    span_q0: Box<Modes>,
    /// The modal coordinates at the end of the last step that ended at a switching, in the
    /// region it left (q0 e^{Λt}, formed with the switching's state).
    q_switch: Box<Modes>,
    /// Stints entered (switchings and restarts), the stint a sample sequence belongs to.
    stints: u64,
    /// The sequence of dense samples ([`Integrator::dense_states_into`], `sample.rs`).
    ///
    /// [`Integrator::dense_states_into`]: crate::integrate::Integrator::dense_states_into
    sampler: sample::SampleCursor,
}

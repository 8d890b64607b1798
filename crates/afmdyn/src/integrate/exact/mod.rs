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
//! after every step, [`Integrator::advance_to`] only at events and at the end). The
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

mod batch;
mod modal;
mod search;
mod spectral;

pub(crate) use crate::linalg::matmul_into;
pub use batch::ExactBatch;
pub use modal::MAX_MODAL_CONDITION;

use super::grid::PeriodGrid;
use super::{ChatterWindow, Integrator, Step};
use crate::error::SimError;
use crate::linalg::kernel::{self, MatVec};
use crate::linalg::matvec;
use crate::model::CantileverModel;
use crate::params::Params;
use crate::params::SweepParam;
use crate::system::Region;
use modal::{ModalExp, Modes, MAXD};
use nalgebra::{DMatrix, DVector, Dyn, LU};
use search::{Search, StepEnds, TipPoly};
use spectral::Spectral;
use std::sync::Arc;

/// Bound on ‖Ã‖₂ h for the grid step (radians of the fastest mode per step).
pub const THETA: f64 = 4.0;
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

/// Amplitude of the base-displacement term α2 sin Ωτ of V_T = W(1,τ) + α2 sin Ωτ + α5 (eq. 8):
/// [`Params::base_amplitude`] (0 for the point-mass model, whose base does not move).
fn base_amp(p: &Params) -> f64 {
    p.base_amplitude()
}

/// [V_T, dV_T/dτ] in a modal region at a time with (sin Ωτ, cos Ωτ) = `sc`, from the tip
/// deflection and rate (w, ẇ) of the homogeneous part: W = w + W_p with the particular part
/// W_p = w0 + ws sin Ωτ + wc cos Ωτ of [`Forced`], then eq. 8
/// ([`CantileverModel::v_t_at`]).
fn modal_v_t(
    model: &CantileverModel,
    fr: &Forced,
    (w, wd): (f64, f64),
    sc: (f64, f64),
) -> (f64, f64) {
    let tip = modal_tip(model.omega(), fr, (w, wd), sc);
    let [v, vd, _] = model.v_t_at(sc, [tip.0, tip.1, 0.0]);
    (v, vd)
}

/// (W(1,τ), ∂W(1,τ)/∂τ) in a modal region at a time with (sin Ωτ, cos Ωτ) = `sc`, from the tip
/// deflection and rate (w, ẇ) of the homogeneous part: W = w + W_p (see [`modal_v_t`]).
#[inline(always)]
fn modal_tip(omega: f64, fr: &Forced, (w, wd): (f64, f64), (s, c): (f64, f64)) -> (f64, f64) {
    let [w0, ws, wc] = fr.wp;
    (w + w0 + ws * s + wc * c, wd + omega * (ws * c - wc * s))
}

/// [`modal_v_t`] at grid point k of a period from the particular part's V_T there
/// ([`Forced`]'s `vp_grid`, formed by `modal_v_t` with w = ẇ = 0): V_T is affine in (w, ẇ), so
/// the whole grid steps of a modal region add two numbers instead of forming eq. 8 again.
#[inline(always)]
fn grid_v_t(fr: &Forced, k: usize, (w, wd): (f64, f64)) -> (f64, f64) {
    let (v, vd) = fr.vp_grid[k];
    (w + v, wd + vd)
}

/// One whole dense grid step k → k + 1: δz = z − z_p(τ_k) into `dz`,
/// y = z_p(τ_{k+1}) + Φ_s δz into `y` (`phi`: Φ_s column-major with its kernel), and
/// [V_T, dV_T/dτ] at τ_{k+1} (eq. 8), given `trig` = (sin Ωτ_{k+1}, cos Ωτ_{k+1}). Slices of
/// length 2N.
#[inline(always)]
fn dense_grid_step(
    model: &CantileverModel,
    fr: &Forced,
    (phi, kernel): (&[f64], MatVec),
    (k, trig): (usize, (f64, f64)),
    z: &[f64],
    dz: &mut [f64],
    y: &mut [f64],
) -> (f64, f64) {
    let dim = z.len();
    let zp = fr.zp_grid.as_slice();
    let (zk, zk1) = (
        &zp[k * dim..(k + 1) * dim],
        &zp[(k + 1) * dim..(k + 2) * dim],
    );
    for ((d, x), a) in dz.iter_mut().zip(z).zip(zk) {
        *d = x - a;
    }
    y.copy_from_slice(zk1);
    kernel(phi, dz, y);
    tip_v_t(model, y, trig)
}

/// [V_T, dV_T/dτ] (eq. 8) of a plain state `z: [f64; 2N]` as (a, ȧ) at a time with
/// (sin Ωτ, cos Ωτ) = `sc`: the tip deflection and rate Σ a_j φ_j(1), Σ ȧ_j φ_j(1) (as
/// [`CantileverModel::w_tip`]), then [`CantileverModel::v_t_at`].
#[inline(always)]
fn tip_v_t(model: &CantileverModel, z: &[f64], sc: (f64, f64)) -> (f64, f64) {
    let n = z.len() / 2;
    let tip = model.tip().as_slice();
    let dot = |x: &[f64]| tip.iter().zip(x).map(|(a, b)| a * b).sum::<f64>();
    let [v, vd, _] = model.v_t_at(sc, [dot(&z[..n]), dot(&z[n..]), 0.0]);
    (v, vd)
}

/// What a run of whole grid steps ([`ExactPropagator`]'s `grid_run`) needs besides the state
/// and sin/cos Ωτ on the grid: the grid, the end time, and the certified test's guard sign σ,
/// dead band and curvature bound.
struct RunLimits {
    grid: PeriodGrid,
    tau_end: f64,
    sigma: f64,
    dead: f64,
    curv: f64,
}

/// The whole grid step of one propagation path, for [`RunLimits::run`].
trait GridSteps {
    /// The step from grid point k (sub-step index) into scratch, not yet taken; returns
    /// [V_T, dV_T/dτ] at its end, given `trig` = (sin Ωτ_{k+1}, cos Ωτ_{k+1}) (the dense step
    /// forms eq. 8 with it; the modal one reads the particular part from [`grid_v_t`]'s table).
    fn try_step(&mut self, k: usize, trig: (f64, f64)) -> (f64, f64);
    /// Take the step tried last (its start is kept as the start of the last step).
    fn accept(&mut self);
}

impl RunLimits {
    /// Whole grid steps from grid point `at` at (τ, (V_T, dV_T/dτ)) = (`tau`, `vt`), each taken
    /// when it ends by `tau_end` and passes the certified test, up to the end of the current
    /// period (`trig`: sin/cos Ωτ on the grid of one period); the step loop of `step_impl` for
    /// these steps, with the same t_grid ([`PeriodGrid::tau`]) and test. Returns the start time
    /// of the last step taken (`None`: none) and whether the run ended at the period end.
    fn run(
        &self,
        trig: &[(f64, f64)],
        tau: &mut f64,
        vt: &mut (f64, f64),
        at: &mut (i64, usize),
        steps: &mut impl GridSteps,
    ) -> (Option<f64>, bool) {
        let mut tau_last = None;
        loop {
            let (p, k) = *at;
            let next = if k + 1 < self.grid.m {
                (p, k + 1)
            } else {
                (p + 1, 0)
            };
            let t_grid = next.0 as f64 * self.grid.period + next.1 as f64 * self.grid.h;
            let len = t_grid - *tau;
            if !(t_grid <= self.tau_end && len > 0.0) {
                return (tau_last, false);
            }
            let vt_b = steps.try_step(k, trig[k + 1]);
            if !StepEnds::new(self.sigma, self.dead, *vt, vt_b, false).certified(self.curv, len) {
                return (tau_last, false);
            }
            steps.accept();
            tau_last = Some(*tau);
            *tau = t_grid;
            *vt = vt_b;
            *at = next;
            if next.1 == 0 {
                return (tau_last, true);
            }
        }
    }
}

/// Dense whole grid steps ([`dense_grid_step`]): the state z and the step's end y swap on
/// acceptance, as do the δz of the step tried and of the last step taken (the propagator's own
/// buffers: no copies, nothing to clear).
struct DenseSteps<'a> {
    model: &'a CantileverModel,
    fr: &'a Forced,
    phi: (&'a [f64], MatVec),
    z: &'a mut DVector<f64>,
    zb: &'a mut DVector<f64>,
    dz_try: &'a mut DVector<f64>,
    dz_last: &'a mut DVector<f64>,
}

impl GridSteps for DenseSteps<'_> {
    fn try_step(&mut self, k: usize, trig: (f64, f64)) -> (f64, f64) {
        dense_grid_step(
            self.model,
            self.fr,
            self.phi,
            (k, trig),
            self.z.as_slice(),
            self.dz_try.as_mut_slice(),
            self.zb.as_mut_slice(),
        )
    }
    fn accept(&mut self) {
        std::mem::swap(self.z, self.zb);
        std::mem::swap(self.dz_try, self.dz_last);
    }
}

/// Modal whole grid steps ([`ModalExp::advance_into`] with e^{Λh}): on acceptance the
/// propagator's three boxed buffers trade places (prev ← cur ← tried ← prev, by pointer), so
/// that after a run q holds the current modal coordinates, `last.q0` the start of the last
/// step and the scratch the free one, without copies.
struct ModalSteps<'a> {
    me: &'a ModalExp,
    fr: &'a Forced,
    cur: &'a mut Box<Modes>,
    tried: &'a mut Box<Modes>,
    prev: &'a mut Box<Modes>,
}

impl GridSteps for ModalSteps<'_> {
    fn try_step(&mut self, k: usize, _trig: (f64, f64)) -> (f64, f64) {
        let tip = self
            .me
            .advance_into(self.cur, &self.fr.grid_fac, self.tried);
        grid_v_t(self.fr, k + 1, tip)
    }
    fn accept(&mut self) {
        std::mem::swap(self.prev, self.cur);
        std::mem::swap(self.cur, self.tried);
    }
}

/// How the grid steps of a region are propagated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Propagation {
    /// Modal wherever the eigenvector basis is well conditioned (condition number ≤
    /// [`MAX_MODAL_CONDITION`] and residual at round-off), dense elsewhere (default): the
    /// faster path at every N measured, N = 1 included (`docs/performance.md`).
    #[default]
    Auto,
    /// Always the dense Φ_s (fixed-size kernel for N ≤ 6).
    Dense,
}

/// Build options of [`ExactPropagator::try_with`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExactOptions {
    /// The grid has a multiple of this many sub-steps per period (≥ 1).
    pub min_steps_per_period: usize,
    /// Propagation of the grid steps.
    pub propagation: Propagation,
    /// Reuse the spectral data and grid exponentials of earlier builds with bit-identical
    /// region matrices (and grid step) — the same values a rebuild computes.
    pub reuse: bool,
}

impl Default for ExactOptions {
    fn default() -> Self {
        ExactOptions {
            min_steps_per_period: 1,
            propagation: Propagation::Auto,
            reuse: true,
        }
    }
}

/// The homogeneous state a tip series is expanded from (`build_poly`): energy coordinates y,
/// or the modal coordinates q of y = V q.
#[derive(Clone, Copy)]
enum SeriesStart<'a> {
    Energy(&'a [f64]),
    Modal(&'a ModalExp, &'a Modes),
}

/// Data of one region that depends on the forcing (Ω, α2, α5) and the grid step.
#[derive(Debug, Clone)]
struct Forced {
    /// Particular solution z_p(τ) = p0 + ps sin Ωτ + pc cos Ωτ.
    p0: DVector<f64>,
    ps: DVector<f64>,
    pc: DVector<f64>,
    /// z_p at the m + 1 grid points of one period (columns).
    zp_grid: DMatrix<f64>,
    /// Tip part of z_p: W_p = w0 + ws sin + wc cos.
    wp: [f64; 3],
    /// Ω² · amplitude of V_p (bound on |V_p''|).
    vp_curv: f64,
    /// [V_T, dV_T/dτ] of the particular solution at the grid points (k = 0..=m).
    vp_grid: Vec<(f64, f64)>,
    /// Ωⁿ/n! and Ωⁿ⁺¹/n!, n = 0..=K: the Taylor factors of the harmonic part of V_T and of
    /// its rate (`build_poly`).
    harm_fact: [[f64; K + 1]; 2],
    /// e^{λ_k h} of the modal representatives (empty without an eigendecomposition).
    grid_fac: Modes,
    /// e^{λ_k h/2}: the modal coordinates at the middle of a grid step, where its tip series
    /// is centred (`step_impl`).
    half_fac: Modes,
    /// LU of [[A, ΩI], [−ΩI, A]] (4N×4N), kept for the parameter derivatives of (ps, pc).
    harmonic_lu: LU<f64, Dyn, Dyn>,
}

/// ∂z_p/∂p of one region's particular solution for a parameter p of the forcing:
/// ∂z_p/∂p(τ) = p0 + ps sin Ωτ + pc cos Ωτ + (∂Ω/∂p) τ (ps⁰ cos Ωτ − pc⁰ sin Ωτ), with
/// (ps⁰, pc⁰) those of [`Forced`]; eq. 10's particular solution differentiated at fixed A:
/// A p0 = −∂b_const/∂p and [[A, ΩI], [−ΩI, A]] (ps, pc) = −(∂b_sin/∂p, ∂b_cos/∂p) −
/// (∂Ω/∂p) (pc⁰, −ps⁰).
#[derive(Debug, Clone)]
struct ParticularDerivative {
    p0: DVector<f64>,
    ps: DVector<f64>,
    pc: DVector<f64>,
    d_omega: f64,
}

/// The last step, kept for dense output.
#[derive(Debug, Clone)]
struct LastStep {
    tau0: f64,
    region: Region,
    /// Homogeneous part δz(τ0) in plain coordinates (dense steps).
    dz0: DVector<f64>,
    /// Modal coordinates of the homogeneous part at τ0 (modal steps; boxed, as the current
    /// coordinates and the scratch, so that a step's buffers trade places by pointer).
    q0: Box<Modes>,
    /// Whether the step was modal.
    modal: bool,
    /// Whether the step was a whole grid step (its transition matrix is Φ_s).
    full: bool,
    /// Sub-step index of the grid point a whole grid step started from.
    k: usize,
}

/// What [`ExactPropagator::step_impl`] forms besides the propagation itself.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Form {
    /// The plain state after every step and the record of an event ([`Integrator::step`]).
    All,
    /// The record of an event; after a step in a modal region the plain state lags behind q
    /// ([`Integrator::step_deferred`]).
    Events,
    /// Neither (inside [`Integrator::advance_to`] and the batch, which read only the result's
    /// `Ok`/`Err`).
    Nothing,
}

/// Exact propagator (see the module docs).
#[derive(Debug, Clone)]
pub struct ExactPropagator {
    model: CantileverModel,
    spec: Arc<[Spectral; 2]>,
    /// Φ_s = e^{A_s h} in plain coordinates.
    phi: Arc<[DMatrix<f64>; 2]>,
    /// Forcing-dependent data of both regions (shared by clones, e.g. the lanes of an
    /// [`ExactBatch`]).
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
    /// z lags behind q (inside [`Integrator::advance_to`]).
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
    param_data: Option<(SweepParam, Arc<[ParticularDerivative; 2]>)>,
    /// ∂z_p/∂p at the end (τ, region) of the last step it was asked for.
    param_end: Option<(f64, Region, [f64; MAXD])>,
    /// The column sums of [`Integrator::displacement_bound`] for the last weights.
    bound_cols: BoundCols,
}

/// Most grid steps over which the stint's bound of [`Integrator::displacement_bound`] is kept
/// (see there).
const STINT_BOUND_STEPS: f64 = 1e5;

/// The tables of [`Integrator::displacement_bound`] for weights c (per region, formed on
/// first use), and the bound of the current stint's homogeneous part.
#[derive(Debug, Clone, Default)]
struct BoundCols {
    weights: Vec<f64>,
    /// Σ_j c_j |b_jk| over the first N rows of T⁻¹V, per modal representative k.
    cols: [Vec<f64>; 2],
    /// Σ_j c_j |a_p,j(τ_k)| at the grid points k = 0..=m (the particular part, from the grid
    /// table of z_p).
    grid: [Vec<f64>; 2],
    /// Whether Re λ_k ≤ 0 for every representative (|q_k| never grows).
    holds: [bool; 2],
    /// (τ, bound) of the homogeneous part formed in the current stint.
    stint: Option<(f64, f64)>,
}

impl BoundCols {
    /// Make the tables those of `weights` in region `ri`.
    fn prepare(&mut self, weights: &[f64], ri: usize, me: &ModalExp, fr: &Forced, n: usize) {
        // the same bits (without an early exit, so that the comparison vectorizes)
        let same = self.weights.len() == weights.len()
            && self
                .weights
                .iter()
                .zip(weights)
                .fold(0, |d, (a, b)| d | (a.to_bits() ^ b.to_bits()))
                == 0;
        if !same {
            self.weights.clear();
            self.weights.extend_from_slice(weights);
            self.cols.iter_mut().for_each(Vec::clear);
            self.grid.iter_mut().for_each(Vec::clear);
            self.stint = None;
        }
        if self.cols[ri].is_empty() {
            let nw = n.min(weights.len());
            self.cols[ri].extend((0..me.len()).map(|k| {
                (0..nw)
                    .map(|j| weights[j] * me.tv.re[(j, k)].hypot(me.tv.im[(j, k)]))
                    .sum::<f64>()
            }));
            let dim = fr.zp_grid.nrows();
            let zp = fr.zp_grid.as_slice().chunks_exact(dim.max(1));
            self.grid[ri].extend(zp.map(|z| crate::model::weighted_displacement(weights, z)));
            self.holds[ri] = me.lambda.iter().all(|l| l.re <= 0.0);
        }
    }

    /// Σ_k cols_k |q_k| in region `ri` (after [`Self::prepare`]).
    fn hom(&self, ri: usize, q: &Modes) -> f64 {
        self.cols[ri]
            .iter()
            .zip(q.re.iter().zip(&q.im))
            .map(|(c, (x, y))| c * (x * x + y * y).sqrt())
            .sum()
    }
}

/// The forcing data of a build, shared by every build with the same key ([`forcing_key`]):
/// both regions' [`Forced`], sin/cos of Ωτ_k on the grid (k = 0..=m) and at the middles of its
/// steps (k + 1/2, k < m).
type Forcing = (Arc<[Forced; 2]>, Arc<[(f64, f64)]>, Arc<[(f64, f64)]>);

/// Recent forcing data (see [`spectral`]'s module docs).
static FORCING: spectral::Cache<Forcing> = std::sync::Mutex::new(Vec::new());

/// Largest forcing data kept in [`FORCING`] (both regions' grid values and the grid's sin/cos):
/// 2 MiB, so its 8 entries hold at most 16 MiB (N = 20 at the default parameters: 1.4 MiB).
const FORCING_KEEP_BYTES: f64 = 2.0 * 1024.0 * 1024.0;

/// Everything [`forced`] and the grid's sin/cos read: the spectral key (A_s, M, K_s), h, Ω,
/// the base-drive amplitude, the gap α5 (V_T on the grid), the tip row and b_const, b_sin, b_cos
/// of both regions, as bits.
fn forcing_key(model: &CantileverModel, spectral_key: &[u64], h: f64) -> Vec<u64> {
    let mut key = spectral_key.to_vec();
    let p = model.params();
    key.extend([h, model.omega(), base_amp(p), p.alpha5].map(f64::to_bits));
    key.extend(model.tip().iter().map(|x| x.to_bits()));
    for r in [Region::Free, Region::Contact] {
        let d = model.dynamics(r);
        for b in [&d.b_const, &d.b_sin, &d.b_cos] {
            key.extend(b.iter().map(|x| x.to_bits()));
        }
    }
    key
}

/// Particular solution of one region and its grid values: A p0 = −b_const and
/// [[A, ΩI], [−ΩI, A]] (ps, pc) = −(b_sin, b_cos) (eq. 10 with harmonic forcing).
fn forced(
    model: &CantileverModel,
    r: Region,
    spec: &Spectral,
    trig: &[(f64, f64)],
    h: f64,
) -> Result<Forced, SimError> {
    let n = model.modes();
    let dim = 2 * n;
    let omega = model.omega();
    let d = model.dynamics(r);
    let p0 = spec
        .a_lu
        .solve(&(-&d.b_const))
        .ok_or_else(|| SimError::out_of_range("state matrix", "singular", "K must be SPD"))?;
    let mut big = DMatrix::zeros(2 * dim, 2 * dim);
    big.view_mut((0, 0), (dim, dim)).copy_from(&d.a);
    big.view_mut((dim, dim), (dim, dim)).copy_from(&d.a);
    for i in 0..dim {
        big[(i, dim + i)] = omega;
        big[(dim + i, i)] = -omega;
    }
    let mut rhs = DVector::zeros(2 * dim);
    rhs.rows_mut(0, dim).copy_from(&(-&d.b_sin));
    rhs.rows_mut(dim, dim).copy_from(&(-&d.b_cos));
    let resonance = || {
        SimError::out_of_range(
            "omega",
            omega,
            "is an undamped natural frequency: no periodic forced response (add damping)",
        )
    };
    let big_norm = big.norm();
    let harmonic_lu = big.lu();
    let sol = harmonic_lu.solve(&rhs).ok_or_else(resonance)?;
    // numerically singular (Ω within round-off of an undamped resonance)
    let amplification = sol.norm() * big_norm;
    if rhs.norm() > 0.0 && (amplification.is_nan() || amplification > 1e13 * rhs.norm()) {
        return Err(resonance());
    }
    let ps = sol.rows(0, dim).into_owned();
    let pc = sol.rows(dim, dim).into_owned();
    let mut zp_grid = DMatrix::zeros(dim, trig.len());
    let (a, b, d) = (p0.as_slice(), ps.as_slice(), pc.as_slice());
    for (col, &(s, c)) in zp_grid.as_mut_slice().chunks_exact_mut(dim).zip(trig) {
        for (((o, a), b), d) in col.iter_mut().zip(a).zip(b).zip(d) {
            *o = a + s * b + c * d;
        }
    }
    let tip = model.tip();
    let wp = [
        tip.dot(&p0.rows(0, n)),
        tip.dot(&ps.rows(0, n)),
        tip.dot(&pc.rows(0, n)),
    ];
    let vp_curv = omega * omega * (wp[1] + base_amp(model.params())).hypot(wp[2]);
    let (mut grid_fac, mut half_fac) = (Modes::ZERO, Modes::ZERO);
    if let Some(me) = &spec.modal {
        me.factors(h, &mut grid_fac);
        me.factors(0.5 * h, &mut half_fac);
    }
    let mut harm_fact = [[0.0; K + 1]; 2];
    let mut om_n = 1.0;
    for n in 0..=K {
        harm_fact[0][n] = om_n * INV_FACT[n];
        harm_fact[1][n] = om_n * omega * INV_FACT[n];
        om_n *= omega;
    }
    let mut fr = Forced {
        p0,
        ps,
        pc,
        zp_grid,
        wp,
        vp_curv,
        harm_fact,
        grid_fac,
        half_fac,
        harmonic_lu,
        vp_grid: Vec::new(),
    };
    fr.vp_grid = trig
        .iter()
        .map(|&sc| modal_v_t(model, &fr, (0.0, 0.0), sc))
        .collect();
    Ok(fr)
}

impl ExactPropagator {
    /// Build the propagator; the grid has a multiple of `min_steps_per_period` sub-steps per
    /// period, refined until ‖Ã_s‖₂ h ≤ θ in both regions.
    ///
    /// # Panics
    /// When the forced response is singular: Ω exactly at an undamped natural frequency
    /// (α3 = 0 and no contact damping), where no periodic particular solution exists.
    pub fn new(model: &CantileverModel, min_steps_per_period: usize) -> Self {
        Self::try_new(model, min_steps_per_period).expect("forced response exists")
    }

    /// As [`ExactPropagator::new`], with an error instead of a panic.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] for Ω at an undamped resonance (see [`ExactPropagator::new`]);
    /// [`SimError::Unsupported`] for a law that is not affine (only the linear law is).
    pub fn try_new(model: &CantileverModel, min_steps_per_period: usize) -> Result<Self, SimError> {
        Self::try_with(
            model,
            ExactOptions {
                min_steps_per_period,
                ..ExactOptions::default()
            },
        )
    }

    /// Build with explicit [`ExactOptions`] (propagation path, reuse of earlier builds).
    ///
    /// # Errors
    /// As [`ExactPropagator::try_new`]; [`SimError::Budget`] when the grid of one period would
    /// exceed [`crate::params::GRID_BUDGET_BYTES`].
    pub fn try_with(model: &CantileverModel, opts: ExactOptions) -> Result<Self, SimError> {
        if !model.law().is_affine() {
            return Err(SimError::Unsupported {
                integrator: "exact",
                law: model.law().name(),
                hint:
                    "only the linear law is piecewise affine: use --integrator adaptive (or auto)",
            });
        }
        let n = model.modes();
        let dim = 2 * n;
        let omega = model.omega();
        let period = model.period();
        let key = spectral::matrix_key(model);
        let (spec, spec_reused) = spectral::spectral(model, &key, opts.reuse)?;
        let rho = spec[0].rho.max(spec[1].rho);
        let base = opts.min_steps_per_period.max(1);
        // budget: the grid of one period, (2N + 2)(m + 1) values, must fit in
        // params::GRID_BUDGET_BYTES; checked in floating point before any allocation
        let need_f = (period * rho / THETA).ceil().max(8.0);
        let m_f = base as f64 * (need_f / base as f64).ceil();
        let bytes = (dim as f64 + 2.0) * (m_f + 1.0) * 8.0;
        if bytes.is_nan() || bytes > crate::params::GRID_BUDGET_BYTES {
            return Err(SimError::Budget {
                what: "exact integrator grid",
                needed: format!(
                    "{m_f:.3e} steps per drive period ({:.0} MiB)",
                    bytes / (1024.0 * 1024.0)
                ),
                budget: "128 MiB".into(),
                hint: "the system is too stiff for its drive period: raise Ω, lower α3, α4, α6 \
                       or N, or lower the samples per period",
            });
        }
        let need = need_f as usize;
        let m = base * need.div_ceil(base);
        let h = period / m as f64;
        let (phi, phi_reused) = spectral::grid_exp(&spec, &key, h, opts.reuse)?;
        // kept only while small: a cache entry outlives the propagators that use it, and the
        // grid of a stiff, large-N build may take up to params::GRID_BUDGET_BYTES
        let keep = (2 * dim + 2) as f64 * (m as f64 + 1.0) * 8.0 <= FORCING_KEEP_BYTES;
        let (forcing, forcing_reused) = spectral::cached(
            &FORCING,
            &forcing_key(model, &key, h),
            opts.reuse && keep,
            || {
                let trig: Vec<(f64, f64)> = (0..=m)
                    .map(|k| (omega * (k as f64 * h)).sin_cos())
                    .collect();
                let trig_mid: Vec<(f64, f64)> = (0..m)
                    .map(|k| (omega * ((2 * k + 1) as f64 * (0.5 * h))).sin_cos())
                    .collect();
                let forced = Arc::new([
                    forced(model, Region::Free, &spec[0], &trig, h)?,
                    forced(model, Region::Contact, &spec[1], &trig, h)?,
                ]);
                Ok((forced, trig.into(), trig_mid.into()))
            },
        )?;
        let (forced, trig, trig_mid) = (forcing.0.clone(), forcing.1.clone(), forcing.2.clone());
        let modal = std::array::from_fn(|i| {
            spec[i].modal.is_some() && opts.propagation == Propagation::Auto
        });
        let p = model.params();
        let scale = forced
            .iter()
            .map(|r| r.wp[1].hypot(r.wp[2]) + r.wp[0].abs())
            .fold(0.0, f64::max);
        let dead = 1e-15 * (1.0 + p.alpha5.abs() + base_amp(p) + scale);
        let zero = DVector::zeros(dim);
        Ok(ExactPropagator {
            model: model.clone(),
            spec,
            phi,
            forced,
            modal,
            reused: (spec_reused, phi_reused, forcing_reused),
            kernel: kernel::for_dim(dim),
            grid: PeriodGrid::new(period, m),
            tau: 0.0,
            z: zero.clone(),
            q: Box::new(Modes::ZERO),
            tip_hom: None,
            stale: false,
            scratch: Box::new(Modes::ZERO),
            region: Region::Free,
            on_grid: Some((0, 0)),
            between: None,
            stint_curvature: 0.0,
            just_switched: true,
            chatter: ChatterWindow::new(CHATTER_COUNT, CHATTER_WINDOW),
            last: LastStep {
                tau0: 0.0,
                region: Region::Free,
                dz0: zero.clone(),
                q0: Box::new(Modes::ZERO),
                modal: false,
                full: false,
                k: 0,
            },
            poly: Box::new(TipPoly::empty()),
            poly_built: false,
            vt: (0.0, 0.0),
            entry_trig: (f64::NAN, (0.0, 1.0)),
            dead,
            trig,
            trig_mid,
            zb: zero.clone(),
            dz_run: zero,
            param_data: None,
            param_end: None,
            bound_cols: BoundCols::default(),
        })
    }

    /// Sub-steps per drive period m.
    pub fn steps_per_period(&self) -> usize {
        self.grid.m
    }

    /// Whether this build reused earlier builds ([`ExactOptions::reuse`]): (the spectral data —
    /// energy transforms, Ã_s, eigendecomposition —, the grid exponentials Φ_s, the forcing
    /// data — particular solutions, their grid values, sin/cos on the grid).
    pub fn reused(&self) -> (bool, bool, bool) {
        self.reused
    }

    /// Whether the grid steps of the free and the contact region (in that order) are modal.
    pub fn modal_regions(&self) -> [bool; 2] {
        self.modal
    }

    /// Transition matrix e^{A_s t} of region `r` in plain coordinates (2N×2N), for
    /// 0 ≤ t ≤ one grid step: the precomputed Φ_s when t is the grid step, else
    /// T⁻¹ e^{Ã t} T column by column (eigendecomposition, or the Taylor series).
    pub fn transition(&self, r: Region, t: f64) -> DMatrix<f64> {
        let dim = self.z.len();
        let mut out = DMatrix::zeros(dim, dim);
        self.transition_into(r, t, &mut out);
        out
    }

    /// [`ExactPropagator::transition`] into `out` (resized to 2N×2N if needed); allocates
    /// nothing with the precomputed Φ_s or the eigendecomposition.
    fn transition_into(&self, r: Region, t: f64, out: &mut DMatrix<f64>) {
        let sp = &self.spec[r.index()];
        let dim = self.z.len();
        if out.shape() != (dim, dim) {
            *out = DMatrix::zeros(dim, dim);
        }
        if t == self.grid.h {
            out.as_mut_slice()
                .copy_from_slice(self.phi[r.index()].as_slice());
            return;
        }
        match &sp.modal {
            // Σ_k Re((T⁻¹v_k) e^{λ_k t} (V⁻¹T)_k): the exponentials once
            Some(me) => me.transition_plain_into(t, out),
            None => {
                let mut e = DMatrix::zeros(dim, dim);
                for j in 0..dim {
                    let mut y = [0.0; MAXD];
                    Self::hom_energy(sp, sp.t.column(j).as_slice(), t, &mut y[..dim]);
                    e.column_mut(j).copy_from_slice(&y[..dim]);
                }
                matmul_into(&sp.tinv, &e, 1.0, out);
            }
        }
    }

    /// Jacobian ∂z(τ1)/∂z(τ0) of the flow over the last step [τ0, τ1] inside its region
    /// (without the saltation at a switching that ends it), 2N×2N: Φ_s or e^{A_s t}.
    pub fn step_transition(&self) -> DMatrix<f64> {
        let dim = self.z.len();
        let mut out = DMatrix::zeros(dim, dim);
        self.step_transition_into(&mut out);
        out
    }

    /// [`ExactPropagator::step_transition`] into `out` (resized to 2N×2N if needed): the
    /// cached Φ_s after a whole grid step, without allocating.
    fn step_transition_into(&self, out: &mut DMatrix<f64>) {
        let len = if self.last_was_grid_step() {
            self.grid.h
        } else {
            self.tau - self.last.tau0
        };
        self.transition_into(self.last.region, len, out);
    }

    /// Whether the last step was a whole grid step that ended on the grid (a switching would
    /// have cut it short): its transition matrix is Φ_s.
    fn last_was_grid_step(&self) -> bool {
        self.last.full && self.on_grid.is_some()
    }

    /// ∂z_p/∂p of both regions for `param` (cached for the last parameter); `None` for a
    /// parameter on which A_s depends.
    fn particular_derivative(
        &mut self,
        param: SweepParam,
    ) -> Result<Option<Arc<[ParticularDerivative; 2]>>, SimError> {
        if let Some((p, d)) = &self.param_data {
            if *p == param {
                return Ok(Some(d.clone()));
            }
        }
        let Some(df) = self.model.forcing_derivative(param) else {
            return Ok(None);
        };
        let singular = || SimError::out_of_range("state matrix", "singular", "K must be SPD");
        let region = |ri: usize| -> Result<ParticularDerivative, SimError> {
            let (fr, d) = (&self.forced[ri], &df[ri]);
            let dim = fr.p0.len();
            let p0 = self.spec[ri]
                .a_lu
                .solve(&(-&d.b_const))
                .ok_or_else(singular)?;
            let mut rhs = DVector::zeros(2 * dim);
            rhs.rows_mut(0, dim)
                .copy_from(&(-&d.b_sin - &fr.pc * d.d_omega));
            rhs.rows_mut(dim, dim)
                .copy_from(&(-&d.b_cos + &fr.ps * d.d_omega));
            let sol = fr.harmonic_lu.solve(&rhs).ok_or_else(singular)?;
            Ok(ParticularDerivative {
                p0,
                ps: sol.rows(0, dim).into_owned(),
                pc: sol.rows(dim, dim).into_owned(),
                d_omega: d.d_omega,
            })
        };
        let data = Arc::new([region(0)?, region(1)?]);
        self.param_data = Some((param, data.clone()));
        self.param_end = None;
        Ok(Some(data))
    }

    /// [`Self::particular_derivative`], with `out` resized to 2N when it is provided.
    #[allow(clippy::type_complexity)]
    fn particular_derivative_for(
        &mut self,
        param: SweepParam,
        out: &mut DVector<f64>,
    ) -> Result<Option<Arc<[ParticularDerivative; 2]>>, SimError> {
        let d = self.particular_derivative(param)?;
        let dim = self.z.len();
        if d.is_some() && out.len() != dim {
            *out = DVector::zeros(dim);
        }
        Ok(d)
    }

    /// ∂z_p/∂p(τ) of one region (see [`ParticularDerivative`]) into `out`, given
    /// (sin Ωτ, cos Ωτ).
    fn zpp_into(
        d: &ParticularDerivative,
        f: &Forced,
        tau: f64,
        (s, c): (f64, f64),
        out: &mut [f64],
    ) {
        let k = d.d_omega * tau;
        let (p0, dps, dpc) = (d.p0.as_slice(), d.ps.as_slice(), d.pc.as_slice());
        let (ps, pc) = (f.ps.as_slice(), f.pc.as_slice());
        for (i, o) in out.iter_mut().enumerate() {
            *o = p0[i] + s * dps[i] + c * dpc[i] + k * (ps[i] * c - pc[i] * s);
        }
    }

    fn zp_into(f: &Forced, omega: f64, tau: f64, out: &mut [f64]) {
        Self::zp_at(f, (omega * tau).sin_cos(), out);
    }

    /// z_p(τ) into `out`, given (sin Ωτ, cos Ωτ).
    fn zp_at(f: &Forced, (s, c): (f64, f64), out: &mut [f64]) {
        let (p0, ps, pc) = (f.p0.as_slice(), f.ps.as_slice(), f.pc.as_slice());
        for (((o, a), b), d) in out.iter_mut().zip(p0).zip(ps).zip(pc) {
            *o = a + s * b + c * d;
        }
    }

    /// out = e^{Ã t} y0 in energy coordinates: the eigendecomposition when available, else
    /// the Taylor series Σ Ãⁿ y0 tⁿ/n!.
    fn hom_energy(sp: &Spectral, y0: &[f64], t: f64, out: &mut [f64]) {
        if let Some(me) = &sp.modal {
            return me.apply(y0, t, out);
        }
        let dim = y0.len();
        let mut term = [0.0; MAXD];
        let mut tmp = [0.0; MAXD];
        let (mut term, mut tmp) = (&mut term[..dim], &mut tmp[..dim]);
        out.copy_from_slice(y0);
        term.copy_from_slice(y0);
        let norm2 = |x: &[f64]| x.iter().map(|v| v * v).sum::<f64>();
        let floor = 1e-34 * norm2(y0);
        for n in 1..=K {
            matvec(&sp.at, term, tmp, t / n as f64, false);
            std::mem::swap(&mut term, &mut tmp);
            for (o, x) in out.iter_mut().zip(term.iter()) {
                *o += x;
            }
            if norm2(term) <= floor {
                break;
            }
        }
    }

    /// Homogeneous part at the start of the last step in energy coordinates.
    fn last_y0(&self, y0: &mut [f64]) {
        let sp = &self.spec[self.last.region.index()];
        match (&sp.modal, self.last.modal) {
            (Some(me), true) => ModalExp::expand(&me.v, &self.last.q0, y0, false),
            _ => matvec(&sp.t, self.last.dz0.as_slice(), y0, 1.0, false),
        }
    }

    /// State at local time t of the last step, in plain coordinates.
    fn state_in_last(&self, t: f64, out: &mut [f64]) {
        let sc = (self.model.omega() * (self.last.tau0 + t)).sin_cos();
        self.state_in_last_at(t, sc, out);
    }

    /// [`Self::state_in_last`] given `sc` = (sin Ωτ, cos Ωτ) at τ = τ0 + t.
    fn state_in_last_at(&self, t: f64, sc: (f64, f64), out: &mut [f64]) {
        let ri = self.last.region.index();
        let sp = &self.spec[ri];
        Self::zp_at(&self.forced[ri], sc, out);
        if let Some(me) = &sp.modal {
            // modal coordinates at τ0 (kept by a modal step, projected from δz by a dense one),
            // advanced by e^{Λt}
            if self.last.modal {
                return me.expand_advanced(&self.last.q0, t, out);
            }
            let mut q0 = Modes::ZERO;
            me.project_plain(self.last.dz0.as_slice(), &mut q0);
            return me.expand_advanced(&q0, t, out);
        }
        let dim = out.len();
        let (mut y0, mut yt) = ([0.0; MAXD], [0.0; MAXD]);
        self.last_y0(&mut y0[..dim]);
        Self::hom_energy(sp, &y0[..dim], t, &mut yt[..dim]);
        matvec(&sp.tinv, &yt[..dim], out, 1.0, true);
    }

    /// z = z_p(τ) + T⁻¹ V q in a modal region, when z lags behind q (after modal steps inside
    /// [`Integrator::advance_to`]). On a grid point z_p is the grid table's value (column k,
    /// or m at a period end), elsewhere z_p(τ) from sin/cos Ωτ, as a materialising step of
    /// `step_impl` forms it: [`Integrator::advance_to`] and the step loop agree bit for bit.
    fn materialize(&mut self) {
        if !self.stale {
            return;
        }
        let ri = self.region.index();
        if let Some(me) = &self.spec[ri].modal {
            let mut z = std::mem::take(&mut self.z);
            self.zp_now(z.as_mut_slice());
            ModalExp::expand(&me.tv, &self.q, z.as_mut_slice(), true);
            self.z = z;
        }
        self.stale = false;
    }

    /// z_p at the current τ in the current region into `out` (`[2N]`): on a grid point the grid
    /// table's value (column k, or m at a period end), elsewhere from sin/cos Ωτ.
    fn zp_now(&self, out: &mut [f64]) {
        let fr = &self.forced[self.region.index()];
        match self.on_grid {
            Some((_, k)) => {
                let (dim, col) = (out.len(), self.grid.table_column(k));
                out.copy_from_slice(&fr.zp_grid.as_slice()[col * dim..(col + 1) * dim]);
            }
            None => Self::zp_into(fr, self.model.omega(), self.tau, out),
        }
    }

    /// (sin Ωτ, cos Ωτ) at the current τ: on a grid point from the grid's table (column k, or m
    /// at a period end, as [`Self::zp_now`]), elsewhere [`Self::trig_at`].
    fn trig_now(&self) -> (f64, f64) {
        match self.on_grid {
            Some((_, k)) => self.trig[self.grid.table_column(k)],
            None => self.trig_at(self.tau),
        }
    }

    /// At the end of a period: form the plain state and stop with [`SimError::Diverged`] when
    /// its norm is NaN or reaches 1e12 ([`crate::params::STATE_NORM_MAX`]).
    fn check_divergence(&mut self) -> Result<(), SimError> {
        self.materialize();
        let norm = self.z.norm();
        if norm.is_nan() || norm >= crate::params::STATE_NORM_MAX {
            return Err(SimError::Diverged {
                tau: self.tau,
                norm,
            });
        }
        Ok(())
    }

    /// Make the last step a zero-length step at the current state, so that dense output and
    /// the step Jacobian refer to it (after [`ExactBatch::advance_to`], whose shared grid steps
    /// keep no per-lane step data).
    fn rest_here(&mut self) {
        self.materialize();
        let ri = self.region.index();
        let dz0 = self.last.dz0.as_mut_slice();
        Self::zp_into(&self.forced[ri], self.model.omega(), self.tau, dz0);
        for (d, z) in dz0.iter_mut().zip(self.z.as_slice()) {
            *d = z - *d;
        }
        self.last.tau0 = self.tau;
        self.last.region = self.region;
        *self.last.q0 = *self.q;
        self.last.modal = self.modal[ri];
        self.last.full = false;
        self.poly_built = false;
    }

    /// Fill `out` with the tip series of a step [τ0, τ0 + len] in region `r`, centred at local
    /// time `center` (with sin, cos Ω(τ0 + center)), from the homogeneous state at τ0 + center
    /// (`start`: energy or modal coordinates). The series reaches |t − center| ≤ max(center,
    /// len − center), half the step when centred, so its terms fall off twice as fast. The
    /// moments c̃ᵀÃⁿy (one product with the precomputed rows, or with the modal table of
    /// [`ModalExp::moments`]), then the Taylor coefficients of g and g′ four terms at a time
    /// (the harmonic factors Ωⁿ/n! from [`Forced`]) until the a priori tail bound is below
    /// round-off (1/n! and 1/n from tables: no division until it passes).
    #[allow(clippy::too_many_arguments)]
    fn build_poly(
        sp: &Spectral,
        fr: &Forced,
        p: &Params,
        dead: f64,
        r: Region,
        (tau0, center, (s0, c0)): (f64, f64, (f64, f64)),
        start: SeriesStart,
        len: f64,
        out: &mut TipPoly,
    ) {
        let radius = center.max(len - center);
        // the harmonic part a_s sin(Ωτc + Ωu) + a_c cos(Ωτc + Ωu) + const of V_T (τc = τ0 +
        // center, u = t − center): its n-th u-derivative at 0 is Ωⁿ (S, C, −S, −C)[n mod 4]
        let (a_s, a_c) = (fr.wp[1] + base_amp(p), fr.wp[2]);
        let (sv, sd) = (a_s * s0 + a_c * c0, a_s * c0 - a_c * s0);
        let (cycle, cyc1) = ([sv, sd, -sv, -sd], [sd, -sv, -sd, sv]);
        // the moments c̃ᵀÃⁿy and a bound |c̃ᵀÃⁿy| ≤ M ρⁿ (from energy coordinates,
        // ‖c̃‖‖y‖ ‖Ã‖₂ⁿ; from modal ones, Σ|w c̃ᵀv_k||q_k| max|λ_k|ⁿ)
        let mo = &mut out.mo;
        let (m_amp, rho) = match start {
            SeriesStart::Energy(y0) => {
                matvec(&sp.rows, y0, mo, 1.0, false);
                let y_norm = y0.iter().map(|v| v * v).sum::<f64>().sqrt();
                (sp.ct_norm * y_norm, sp.rho)
            }
            SeriesStart::Modal(me, q) => (me.moments(q, mo), me.lambda_max),
        };
        // a priori bound on the coefficients beyond n: |c̃ᵀÃ^{n+d}y| rⁿ/n! ≤ M ρ^{n+d} rⁿ/n!
        // and |harmonic| ≤ (|a_s| + |a_c|) Ω^{n+d} rⁿ/n! (d ≤ 2, r the radius), so with
        // x = max(ρ, Ω) r every size below is ≤ bound xⁿ/n! and the tail from n on
        // ≤ bound xⁿ/n! / (1 − x/(n+1)): the series stop as soon as that is below round-off of
        // the largest term so far
        let (om, amp) = (p.omega, a_s.abs() + a_c.abs());
        let bound = m_amp * (1.0 + rho + rho * rho) * 3.0 + amp * (1.0 + om + om * om) * 2.0;
        let wp_sum = fr.wp.iter().map(|x| x.abs()).sum::<f64>();
        let x = rho.max(om) * radius;
        let [hf0, hf1] = &fr.harm_fact;
        // in blocks of four terms (the harmonic cycle is the same in every block, and the lanes
        // of a block are independent): every term's coefficients, the size of its contribution
        // over the step (sums rather than maxima: a bound as good, without NaN-aware max
        // sequences) and its share of the bound on |g''|; then the block's terms in order until
        // the a priori tail is below round-off
        let mut size = [0.0; K + 1];
        let mut curv_n = [0.0; 4];
        let (mut biggest, mut x_pow, mut filled) = (0.0f64, x, K + 1);
        let mut curv = fr.vp_curv;
        let mut l = 1.0;
        'blocks: for j in 0..TERM_BLOCKS {
            // rⁿ of the block's terms
            let mut lp = [0.0; 4];
            for o in lp.iter_mut() {
                *o = l;
                l *= radius;
            }
            for i in 0..4 {
                let n = 4 * j + i;
                let f = INV_FACT[n];
                let (c0n, c1n, c2n) = (mo[n] * f, mo[n + 1] * f, mo[n + 2] * f);
                let g0 = c0n + hf0[n] * cycle[i];
                let g1 = c1n + hf1[n] * cyc1[i];
                out.gc[0][n] = g0;
                out.gc[1][n] = g1;
                curv_n[i] = c2n.abs() * lp[i];
                size[n] = (c0n.abs() + c1n.abs() + c2n.abs() + g0.abs() + g1.abs()) * lp[i];
            }
            for n in 4 * j..4 * j + 4 {
                if size[n] > biggest {
                    biggest = size[n];
                }
                curv += curv_n[n - 4 * j];
                // the tail from n + 1 on: bound xⁿ⁺¹/(n+1)! / (1 − x/(n+2))
                let x_fact = x_pow * INV_FACT[n + 1];
                let ratio = x * INV_INT[n + 2];
                x_pow *= x;
                if ratio < 0.5 && bound * x_fact <= 1e-18 * (biggest + wp_sum) * (1.0 - ratio) {
                    filled = n + 1;
                    curv += bound * x_fact / (1.0 - ratio);
                    break 'blocks;
                }
            }
        }
        out.gc[0][0] += fr.wp[0] + p.alpha5;
        let scale = biggest + wp_sum;
        let mut terms = filled;
        let mut tail = 0.0;
        while terms > 1 {
            tail += size[terms - 1];
            if tail > 1e-18 * scale {
                break;
            }
            terms -= 1;
        }
        out.tau0 = tau0;
        out.center = center;
        out.terms = terms;
        out.wp = fr.wp;
        out.omega = p.omega;
        out.trig_c = (s0, c0);
        out.cycle = cycle;
        out.sigma = r.guard_sign();
        out.dead = dead;
        out.curv = curv;
        out.refilled();
    }

    /// (sin Ωτ, cos Ωτ): kept from the last switching or reset when τ is its time (the start
    /// of the step after it), formed otherwise.
    fn trig_at(&self, tau: f64) -> (f64, f64) {
        match self.entry_trig {
            (t, sc) if t == tau => sc,
            _ => (self.model.omega() * tau).sin_cos(),
        }
    }

    /// Build the tip series of the last step (unless the step built it), covering local time
    /// t (dense output).
    fn poly_for_last(&mut self, t: f64) {
        if self.poly_built {
            return;
        }
        let step = self.tau - self.last.tau0;
        self.build_last_series(step.max(t), t <= step);
    }

    /// Build the tip series of the last step over local times [0, `len`]: for a whole modal
    /// grid step (when `centred`), centred at its middle from the modal coordinates there
    /// (q0 e^{Λh/2}), so that it reaches half the step; otherwise from the step's start in
    /// energy coordinates. The switching search (`step_impl`) and dense output
    /// ([`Self::poly_for_last`]) use the same series of a step.
    fn build_last_series(&mut self, len: f64, centred: bool) {
        let ri = self.last.region.index();
        let dim = self.z.len();
        let mut y0 = [0.0; MAXD];
        let (center, start) = match (
            &self.spec[ri].modal,
            centred && self.last.modal && self.last.full,
        ) {
            (Some(me), true) => {
                let mid = &mut self.scratch;
                mid.copy_prefix(&self.last.q0, me.len());
                mid.mul_assign(&self.forced[ri].half_fac, me.len());
                (
                    (self.last.tau0, 0.5 * len, self.trig_mid[self.last.k]),
                    SeriesStart::Modal(me, &self.scratch),
                )
            }
            _ => {
                self.last_y0(&mut y0[..dim]);
                let tau0 = self.last.tau0;
                (
                    (tau0, 0.0, self.trig_at(tau0)),
                    SeriesStart::Energy(&y0[..dim]),
                )
            }
        };
        Self::build_poly(
            &self.spec[ri],
            &self.forced[ri],
            self.model.params(),
            self.dead,
            self.last.region,
            center,
            start,
            len,
            &mut self.poly,
        );
        self.poly_built = true;
    }

    /// Start a stint in `region` at (τ, z): the bound on |W_hom''| over the whole stint and, with
    /// the eigendecomposition, the modal coordinates q = V⁻¹ T δz of the homogeneous part. With
    /// y(t) = Σ v_k e^{λ_k t} q_k the bound is the modal Σ |c̃ᵀv_k| |λ_k|² |q_k| (Re λ_k ≤ 0);
    /// without it, the energy bound ‖c̃ᵀÃ²‖ ‖y‖ (‖e^{Ãt}‖₂ ≤ 1), which is never the smaller one
    /// where both exist (none of 820 stint entries at N = 3 and 358 at N = 10 on the default
    /// attractor). `sc` = (sin Ωτ, cos Ωτ) at the entry time τ.
    fn enter_stint(&mut self, region: Region, sc: (f64, f64)) {
        let ri = region.index();
        let sp = &self.spec[ri];
        // δz and y in the two scratch vectors (free between steps)
        let (dz, y) = (self.zb.as_mut_slice(), self.dz_run.as_mut_slice());
        Self::zp_at(&self.forced[ri], sc, dz);
        for (d, z) in dz.iter_mut().zip(self.z.as_slice()) {
            *d = z - *d;
        }
        self.bound_cols.stint = None;
        self.tip_hom = None;
        self.stint_curvature = match &sp.modal {
            Some(me) => {
                me.project_plain(dz, &mut self.q);
                me.curvature(&self.q) * (1.0 + 1e-12)
            }
            None => {
                matvec(&sp.t, dz, y, 1.0, false);
                sp.kappa2 * y.iter().map(|v| v * v).sum::<f64>().sqrt()
            }
        };
    }

    /// Whole grid steps from the current grid point, as long as each ends by `tau_end` and
    /// passes the certified test — the common case between switchings — exactly as
    /// [`Self::step_impl`] with [`Form::Nothing`] takes them (the same operations in the same
    /// order, so bit for bit the same states, V_T and last step), without its per-step
    /// bookkeeping. Stops before a step that would end off the grid or beyond `tau_end`, or
    /// that fails the test (`step_impl` then takes it, with the search), and right after a
    /// switching or [`Integrator::reset`]. At each period end the plain state is formed and
    /// checked as `step_impl` does ([`Self::check_divergence`]).
    fn grid_run(&mut self, tau_end: f64) -> Result<(), SimError> {
        if self.just_switched {
            return Ok(());
        }
        let ri = self.region.index();
        let modal = self.modal[ri] && self.spec[ri].modal.is_some();
        loop {
            let at_period_end = if modal {
                self.modal_run(tau_end)
            } else {
                self.dense_run(tau_end)
            };
            if !at_period_end {
                return Ok(());
            }
            self.check_divergence()?;
        }
    }

    /// [`Self::grid_run`] in a dense region: z ← z_p(τ_{k+1}) + Φ_s (z − z_p(τ_k)). Returns
    /// whether it stopped at the end of a period.
    fn dense_run(&mut self, tau_end: f64) -> bool {
        let Some(mut at) = self.on_grid else {
            return false;
        };
        let limits = self.run_limits(tau_end);
        let ExactPropagator {
            ref model,
            ref phi,
            ref forced,
            kernel,
            ref trig,
            ref mut tau,
            ref mut vt,
            ref mut z,
            ref mut zb,
            ref mut dz_run,
            region,
            ref mut last,
            ..
        } = *self;
        let ri = region.index();
        let mut steps = DenseSteps {
            model,
            fr: &forced[ri],
            phi: (phi[ri].as_slice(), kernel),
            z,
            zb,
            dz_try: dz_run,
            dz_last: &mut last.dz0,
        };
        let (ran, period_end) = limits.run(trig, tau, vt, &mut at, &mut steps);
        let Some(tau0) = ran else {
            return false;
        };
        self.finish_run(tau0, at, false);
        period_end
    }

    /// [`Self::grid_run`] in a modal region: q ← e^{Λh} ⊙ q, the plain state not formed (as
    /// `step_impl` with [`Form::Nothing`]). Returns whether it stopped at the end of a period.
    fn modal_run(&mut self, tau_end: f64) -> bool {
        let Some(mut at) = self.on_grid else {
            return false;
        };
        let limits = self.run_limits(tau_end);
        let ExactPropagator {
            ref spec,
            ref forced,
            ref trig,
            ref mut tau,
            ref mut vt,
            ref mut q,
            ref mut scratch,
            region,
            ref mut last,
            ..
        } = *self;
        let ri = region.index();
        let (Some(me), fr) = (&spec[ri].modal, &forced[ri]) else {
            return false;
        };
        let mut steps = ModalSteps {
            me,
            fr,
            cur: q,
            tried: scratch,
            prev: &mut last.q0,
        };
        let (ran, period_end) = limits.run(trig, tau, vt, &mut at, &mut steps);
        let Some(tau0) = ran else {
            return false;
        };
        // (the runs of `advance_to` keep no tip: nobody reads it there)
        self.tip_hom = None;
        self.finish_run(tau0, at, true);
        period_end
    }

    /// The limits of a run in the current stint up to `tau_end`.
    fn run_limits(&self, tau_end: f64) -> RunLimits {
        RunLimits {
            grid: self.grid,
            tau_end,
            sigma: self.region.guard_sign(),
            dead: self.dead,
            curv: self.stint_curvature + self.forced[self.region.index()].vp_curv,
        }
    }

    /// After a run that took whole grid steps, the last of them from `tau0`, to grid point
    /// `at`: the last-step record of a whole grid step (as `step_impl` leaves it).
    fn finish_run(&mut self, tau0: f64, at: (i64, usize), modal: bool) {
        self.last.tau0 = tau0;
        self.last.region = self.region;
        self.last.full = true;
        self.last.modal = modal;
        self.last.k = at.1.checked_sub(1).unwrap_or(self.grid.m - 1);
        self.on_grid = Some(at);
        self.poly_built = false;
        // z lags behind q after modal steps (formed by materialize)
        self.stale = modal;
    }

    /// One step (see [`Integrator::step`]), forming what `form` asks for: with
    /// [`Form::Events`] and [`Form::Nothing`] the plain state at the end of a step in a modal
    /// region is not formed (z lags behind q), and with [`Form::Nothing`] a switching is
    /// returned without its event record (no copy of the state).
    pub(super) fn step_impl(&mut self, tau_max: f64, form: Form) -> Result<Step, SimError> {
        let region = self.region;
        let tau0 = self.tau;
        let omega = self.model.omega();
        let m = self.grid.m;
        let next = match self.on_grid {
            Some((p, k)) if k + 1 < m => (p, k + 1),
            Some((p, _)) => (p + 1, 0),
            None => match self.between {
                Some((next, t_next)) if tau0 < t_next => next,
                _ => {
                    let j = self.grid.next_index(tau0);
                    (j.div_euclid(m as i64), j.rem_euclid(m as i64) as usize)
                }
            },
        };
        // as PeriodGrid::tau
        let t_grid = next.0 as f64 * self.grid.period + next.1 as f64 * self.grid.h;
        let tau_b = t_grid.min(tau_max);
        let len = tau_b - tau0;
        if len <= 0.0 {
            return Ok(Step {
                tau0,
                tau1: tau0,
                region,
                event: None,
            });
        }
        let full = self.on_grid.is_some() && tau_b == t_grid;
        // this step ends by t_grid, and until t_grid the next grid point stays `next`
        self.between = Some((next, t_grid));
        let k = self.on_grid.map_or(0, |(_, k)| k);
        let ri = region.index();
        let modal = self.modal[ri];
        let dim = self.z.len();
        self.poly_built = false;
        self.last.tau0 = tau0;
        self.last.region = region;
        self.last.full = full;
        self.last.modal = modal;
        self.last.k = k;
        let fr = &self.forced[ri];
        let mut end_state = true;
        // sin, cos Ωτ_b: from the grid's table when the step ends on a grid point (column k, or
        // m at a period end, as a whole grid step to it and `materialize` take them)
        let trig_b = if tau_b == t_grid {
            self.trig[self.grid.table_column(next.1)]
        } else {
            (omega * tau_b).sin_cos()
        };
        let vt_b = match (&self.spec[ri].modal, modal) {
            (Some(me), true) => {
                // q ← e^{Λ len} q; the tip from q
                let fac = if full {
                    &fr.grid_fac
                } else {
                    me.factors(len, &mut self.scratch);
                    &self.scratch
                };
                // into last.q0, then the two trade places: q the step's end, last.q0 its start
                let (w, wd) = me.advance_into(&self.q, fac, &mut self.last.q0);
                std::mem::swap(&mut self.q, &mut self.last.q0);
                self.tip_hom = Some((w, wd));
                if form != Form::All {
                    end_state = false;
                } else {
                    let zb = self.zb.as_mut_slice();
                    if full {
                        zb.copy_from_slice(&fr.zp_grid.as_slice()[(k + 1) * dim..(k + 2) * dim]);
                    } else {
                        Self::zp_at(fr, trig_b, zb);
                    }
                    ModalExp::expand(&me.tv, &self.q, zb, true);
                }
                if full {
                    grid_v_t(fr, k + 1, (w, wd))
                } else {
                    modal_v_t(&self.model, fr, (w, wd), trig_b)
                }
            }
            _ if full => dense_grid_step(
                &self.model,
                fr,
                (self.phi[ri].as_slice(), self.kernel),
                (k, self.trig[k + 1]),
                self.z.as_slice(),
                self.last.dz0.as_mut_slice(),
                self.zb.as_mut_slice(),
            ),
            _ => {
                // sin, cos at τ0 (kept from a switching or reset there); at τ_b once (τ0 + len
                // is τ_b but for rounding, when τ_b > 2τ0)
                let sc0 = self.trig_at(tau0);
                let dz0 = self.last.dz0.as_mut_slice();
                Self::zp_at(fr, sc0, dz0);
                for (d, z) in dz0.iter_mut().zip(self.z.as_slice()) {
                    *d = z - *d;
                }
                let sc_b = trig_b;
                let sc_end = if tau0 + len == tau_b {
                    sc_b
                } else {
                    (omega * (tau0 + len)).sin_cos()
                };
                let mut zb = std::mem::take(&mut self.zb);
                self.state_in_last_at(len, sc_end, zb.as_mut_slice());
                let v = tip_v_t(&self.model, zb.as_slice(), sc_b);
                self.zb = zb;
                v
            }
        };
        let ends = StepEnds::new(
            region.guard_sign(),
            self.dead,
            self.vt,
            vt_b,
            self.just_switched,
        );
        let StepEnds {
            ga,
            da,
            gb,
            db,
            switched,
        } = ends;
        let cheap = self.stint_curvature + self.forced[ri].vp_curv;
        let mut hit = None;
        if !ends.certified(cheap, len) {
            self.build_last_series(len, true);
            // both bound |g''| over the step: the series' sum of absolute terms (a cosh-like
            // overestimate of an oscillation) is often the larger one
            self.poly.curv = self.poly.curv.min(cheap);
            let poly = &*self.poly;
            let search = Search { poly };
            // start of the search: after a switching, where the lower parabola peaks
            let mut a = 0.0;
            let mut g_a = (ga, da);
            if switched {
                a = if da > 0.0 && poly.curv > 0.0 {
                    (da / poly.curv).min(0.5 * len)
                } else {
                    (4.0 * f64::EPSILON * (1.0 + tau0.abs())).min(0.5 * len)
                };
                g_a = poly.g(a);
            }
            if g_a.0 <= 0.0 {
                hit = Some(a);
            } else {
                hit = search.first(a, g_a, len, (gb, db), 0);
            }
        }
        self.just_switched = false;
        match hit {
            None => {
                if end_state {
                    std::mem::swap(&mut self.z, &mut self.zb);
                    self.stale = false;
                } else {
                    self.stale = true;
                }
                self.tau = tau_b;
                self.vt = vt_b;
                self.on_grid = (tau_b == t_grid).then_some(next);
                if let Some((_, k_next)) = self.on_grid {
                    if k_next == 0 {
                        self.check_divergence()?;
                    }
                }
                Ok(Step {
                    tau0,
                    tau1: tau_b,
                    region,
                    event: None,
                })
            }
            Some(t) => {
                let tau_s = tau0 + t;
                let sc = (omega * tau_s).sin_cos();
                let mut zs = std::mem::take(&mut self.z);
                self.state_in_last_at(t, sc, zs.as_mut_slice());
                self.z = zs;
                self.stale = false;
                let to = region.other();
                self.tau = tau_s;
                self.vt = tip_v_t(&self.model, self.z.as_slice(), sc);
                self.region = to;
                self.on_grid = None;
                self.just_switched = true;
                self.entry_trig = (tau_s, sc);
                self.enter_stint(to, sc);
                self.chatter.record(tau_s)?;
                if form == Form::Nothing {
                    return Ok(Step {
                        tau0,
                        tau1: tau_s,
                        region,
                        event: None,
                    });
                }
                Ok(Step::switched(&self.model, tau0, region, tau_s, &self.z))
            }
        }
    }
}

impl Integrator for ExactPropagator {
    fn model(&self) -> &CantileverModel {
        &self.model
    }
    fn tau(&self) -> f64 {
        self.tau
    }
    fn state(&self) -> &DVector<f64> {
        &self.z
    }
    fn region(&self) -> Region {
        self.region
    }
    fn name(&self) -> &'static str {
        "exact"
    }

    fn reset(&mut self, tau: f64, z: &DVector<f64>) -> Result<(), SimError> {
        let (region, z) = self.model.checked_start(tau, z)?;
        self.region = region;
        self.tau = tau;
        self.z.copy_from(&z);
        self.stale = false;
        let j = self.grid.next_index(tau) - 1;
        let m = self.grid.m as i64;
        self.on_grid =
            (self.grid.tau(j) == tau).then_some((j.div_euclid(m), j.rem_euclid(m) as usize));
        self.between = None;
        let sc = (self.model.omega() * tau).sin_cos();
        self.entry_trig = (tau, sc);
        self.enter_stint(region, sc);
        self.just_switched = true;
        self.chatter.clear();
        self.last.tau0 = tau;
        self.last.region = region;
        self.last.dz0.fill(0.0);
        *self.last.q0 = Modes::ZERO;
        self.last.modal = false;
        self.last.full = false;
        self.poly_built = false;
        self.param_end = None;
        self.vt = tip_v_t(&self.model, z.as_slice(), sc);
        Ok(())
    }

    fn step(&mut self, tau_max: f64) -> Result<Step, SimError> {
        self.step_impl(tau_max, Form::All)
    }

    fn step_deferred(&mut self, tau_max: f64) -> Result<Step, SimError> {
        self.step_impl(tau_max, Form::Events)
    }

    fn form_state(&mut self) {
        self.materialize();
    }

    /// V_T and dV_T/dτ of the switching test at the end of the last step; W and ∂W/∂τ from the
    /// plain state, or, while it lags behind, from the modal coordinates: Σ_k Re(w_k c̃ᵀv_k q_k)
    /// (and with λ_k; as the last step returned them, else `ModalExp::tip_of`) plus the
    /// particular part (`modal_tip`).
    fn tip_values(&self) -> [f64; 4] {
        let (v, vd) = self.vt;
        let ri = self.region.index();
        let (w, wd) = match (&self.spec[ri].modal, self.stale) {
            (Some(me), true) => modal_tip(
                self.model.omega(),
                &self.forced[ri],
                self.tip_hom.unwrap_or_else(|| me.tip_of(&self.q)),
                self.trig_now(),
            ),
            _ => (self.model.w_tip(&self.z), self.model.w_tip_dot(&self.z)),
        };
        [w, wd, v, vd]
    }

    /// While the plain state lags behind the modal coordinates: a = a_p(τ) + Σ_k Re(b_k q_k)
    /// (the first N rows b_k of T⁻¹V, `ModalExp::expand`), and |Re(b q)| ≤ |b| |q|, so
    /// Σ_j c_j |a_j| ≤ Σ_j c_j |a_p,j| + Σ_k (Σ_j c_j |b_jk|) |q_k| (|q_k| as √(Re² + Im²):
    /// within a few ulp, which the 1e-9 widening of the body-contact test covers; the states
    /// are below 1e12, far from overflow). Where Re λ_k ≤ 0 for every k, |q_k| does not grow
    /// along a stint (q_k(τ) = e^{λ_k (τ − τ_0)} q_k(τ_0)), so the homogeneous part's sum
    /// formed once in a stint bounds it at every later point of the stint: with the
    /// particular part from a table on the grid that is O(1) per step, returned when below
    /// `enough`. It is widened by 1e-10 and formed again after a period or 10⁵ grid steps,
    /// whichever is shorter: the rounding of one step's complex product can grow a computed
    /// |q_k| by a few ulp, at most about 6e-11 over 10⁵ steps. Otherwise the sum at the
    /// current q. Without modal coordinates, the sum itself.
    fn displacement_bound(&mut self, weights: &[f64], enough: f64) -> f64 {
        let ri = self.region.index();
        let (Some(me), true) = (&self.spec[ri].modal, self.stale) else {
            return crate::model::weighted_displacement(weights, self.z.as_slice());
        };
        let cache = &mut self.bound_cols;
        cache.prepare(weights, ri, me, &self.forced[ri], self.model.modes());
        let part = match self.on_grid {
            Some((_, k)) => cache.grid[ri][self.grid.table_column(k)],
            None => {
                // z_p in the scratch vector (free between steps)
                let mut zp = std::mem::take(&mut self.zb);
                self.zp_now(zp.as_mut_slice());
                let part = crate::model::weighted_displacement(weights, zp.as_slice());
                self.zb = zp;
                part
            }
        };
        // the stint's bound is kept over a period, at most STINT_BOUND_STEPS grid steps
        let window = self.grid.h * (self.grid.m as f64).min(STINT_BOUND_STEPS);
        let cache = &mut self.bound_cols;
        if cache.holds[ri] {
            let stint = match cache.stint {
                Some((tau, h)) if self.tau - tau <= window => h,
                _ => {
                    let h = cache.hom(ri, &self.q) * (1.0 + 1e-10);
                    cache.stint = Some((self.tau, h));
                    h
                }
            };
            if part + stint < enough {
                return part + stint;
            }
        }
        part + cache.hom(ri, &self.q)
    }

    fn advance_to(&mut self, tau_end: f64) -> Result<(), SimError> {
        let mut out = Ok(());
        while self.tau < tau_end {
            // the certified whole grid steps in one tight loop, the next step (a possible
            // switching, or a partial step) by step_impl
            let step = self.grid_run(tau_end).and_then(|()| {
                if self.tau < tau_end {
                    self.step_impl(tau_end, Form::Nothing)?;
                }
                Ok(())
            });
            if let Err(e) = step {
                out = Err(e);
                break;
            }
        }
        self.materialize();
        out
    }

    fn dense_tip(&mut self, tau: f64) -> [f64; 3] {
        let t = tau - self.last.tau0;
        self.poly_for_last(t);
        self.poly.w(t)
    }

    /// From the tip series of the last step, whose coefficients include the harmonic part of
    /// V_T (eq. 8): no sine per call, unlike the default through [`Integrator::dense_tip`].
    fn dense_v_t(&mut self, tau: f64) -> [f64; 3] {
        let t = tau - self.last.tau0;
        self.poly_for_last(t);
        self.poly.v_t(t)
    }

    fn dense_state(&mut self, tau: f64) -> DVector<f64> {
        let mut out = DVector::zeros(self.z.len());
        self.state_in_last(tau - self.last.tau0, out.as_mut_slice());
        out
    }

    fn last_step_jacobian(&mut self) -> Result<DMatrix<f64>, SimError> {
        Ok(self.step_transition())
    }

    /// z(τ1) = z_p(τ1) + e^{A t}(z(τ0) − z_p(τ0)) with A independent of p, so at fixed z(τ0)
    /// ∂z(τ1)/∂p = ∂z_p/∂p(τ1) − e^{A t} ∂z_p/∂p(τ0).
    fn last_step_param_derivative_into(
        &mut self,
        param: SweepParam,
        out: &mut DVector<f64>,
    ) -> Result<bool, SimError> {
        let Some(d) = self.particular_derivative_for(param, out)? else {
            return Ok(false);
        };
        let dim = self.z.len();
        let (r, ta, tb) = (self.last.region, self.last.tau0, self.tau);
        let ri = r.index();
        let omega = self.model.omega();
        // ∂z_p/∂p at τa: the τb value of the previous call when the steps join in one region
        // (every grid step of a stint), and sin, cos from the grid table on the grid
        let mut xa = [0.0; MAXD];
        let xa = &mut xa[..dim];
        match &self.param_end {
            Some((tau, region, x)) if *tau == ta && *region == r => xa.copy_from_slice(&x[..dim]),
            _ => Self::zpp_into(&d[ri], &self.forced[ri], ta, (omega * ta).sin_cos(), xa),
        }
        let trig_b = match self.on_grid {
            Some((_, k)) => self.trig[k],
            None => (omega * tb).sin_cos(),
        };
        Self::zpp_into(&d[ri], &self.forced[ri], tb, trig_b, out.as_mut_slice());
        let end = self.param_end.get_or_insert((0.0, r, [0.0; MAXD]));
        end.0 = tb;
        end.1 = r;
        end.2[..dim].copy_from_slice(out.as_slice());
        // out −= e^{A t} xa: Φ_s after a whole grid step, else T⁻¹ e^{Ã t} T xa
        let sp = &self.spec[ri];
        if self.last_was_grid_step() {
            matvec(&self.phi[ri], xa, out.as_mut_slice(), -1.0, true);
        } else {
            let (mut y0, mut yt) = ([0.0; MAXD], [0.0; MAXD]);
            matvec(&sp.t, xa, &mut y0[..dim], 1.0, false);
            Self::hom_energy(sp, &y0[..dim], tb - ta, &mut yt[..dim]);
            matvec(&sp.tinv, &yt[..dim], out.as_mut_slice(), -1.0, true);
        }
        Ok(true)
    }

    fn region_particular_param_derivative_into(
        &mut self,
        param: SweepParam,
        r: Region,
        tau: f64,
        out: &mut DVector<f64>,
    ) -> Result<bool, SimError> {
        let Some(d) = self.particular_derivative_for(param, out)? else {
            return Ok(false);
        };
        let ri = r.index();
        let sc = (self.model.omega() * tau).sin_cos();
        Self::zpp_into(&d[ri], &self.forced[ri], tau, sc, out.as_mut_slice());
        Ok(true)
    }

    fn has_region_transition(&self, r: Region) -> bool {
        self.spec[r.index()].modal.is_some()
    }

    /// T⁻¹ V e^{Λt} V⁻¹ T from the eigendecomposition (accurate for any t ≥ 0: Re λ_k ≤ 0 and
    /// the basis is well conditioned, [`modal::MAX_MODAL_CONDITION`]).
    fn region_transition_into(&self, r: Region, t: f64, out: &mut DMatrix<f64>) -> bool {
        let Some(me) = &self.spec[r.index()].modal else {
            return false;
        };
        let dim = self.z.len();
        if out.shape() != (dim, dim) {
            *out = DMatrix::zeros(dim, dim);
        }
        me.transition_plain_into(t, out);
        true
    }

    fn last_step_jacobian_into(&mut self, out: &mut DMatrix<f64>) -> Result<(), SimError> {
        self.step_transition_into(out);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The homogeneous tip deflection and rate a modal grid step returns are those
    /// `ModalExp::tip_of` reads from its result, bit for bit (`tip_values` takes the first after
    /// a step of `step_impl`, the second after a run or the batch), and both are c̃ᵀy and c̃ᵀÃy
    /// of the state y = V q formed in energy coordinates, to round-off; an odd (N = 1, 3) and
    /// an even (N = 8) number of representatives, both regions.
    #[test]
    fn modal_step_tip_is_the_tip_of_its_result() {
        for modes in [1usize, 3, 8] {
            let model = CantileverModel::new(&Params {
                modes,
                ..Params::default()
            })
            .unwrap();
            let prop = ExactPropagator::try_new(&model, 1).unwrap();
            let dim = 2 * modes;
            for ri in 0..2 {
                let (sp, fr) = (&prop.spec[ri], &prop.forced[ri]);
                let me = sp.modal.as_ref().expect("well conditioned");
                let y0 = DVector::from_fn(dim, |j, _| (0.7 * j as f64 + 0.3).sin());
                let (mut q, mut out) = (Modes::ZERO, Modes::ZERO);
                me.project(y0.as_slice(), &mut q);
                for _ in 0..5 {
                    let stepped = me.advance_into(&q, &fr.grid_fac, &mut out);
                    let read = me.tip_of(&out);
                    assert_eq!(stepped.0.to_bits(), read.0.to_bits(), "N = {modes}");
                    assert_eq!(stepped.1.to_bits(), read.1.to_bits(), "N = {modes}");
                    let mut y = vec![0.0; dim];
                    ModalExp::expand(&me.v, &out, &mut y, false);
                    let row = |n: usize| (0..dim).map(|j| sp.rows[(n, j)] * y[j]).sum::<f64>();
                    let scale = sp.ct_norm * y0.norm() * (1.0 + sp.rho);
                    assert!((read.0 - row(0)).abs() <= 1e-13 * scale, "N = {modes}");
                    assert!((read.1 - row(1)).abs() <= 1e-13 * scale, "N = {modes}");
                    q = out;
                }
            }
        }
    }

    /// The tip series of a step — expanded at its start, and centred at its middle from the
    /// energy coordinates there or from the modal ones (the moments of
    /// [`ModalExp::moments`]) — equal the gap g = σ V_T + dead and its rate from the closed-form
    /// homogeneous solution c̃ᵀ e^{Ãt} y0 (nalgebra's matrix exponential, independent of the
    /// eigendecomposition) plus the harmonic part of eq. 8, to round-off over the whole step,
    /// in both regions, at N = 1, 3 and 8; and so does the dense tip deflection [W, W', W''].
    #[test]
    fn tip_series_equal_the_closed_form() {
        for modes in [1usize, 3, 8] {
            let p = Params {
                modes,
                ..Params::default()
            };
            let model = CantileverModel::new(&p).unwrap();
            let prop = ExactPropagator::try_new(&model, 1).unwrap();
            let (h, dim) = (prop.grid.h, 2 * modes);
            for (ri, r) in [Region::Free, Region::Contact].into_iter().enumerate() {
                let (sp, fr) = (&prop.spec[ri], &prop.forced[ri]);
                let me = sp.modal.as_ref().expect("well conditioned");
                let y0 = DVector::from_fn(dim, |j, _| (0.7 * j as f64 + 0.3).sin());
                let tau0 = 1.234;
                let y_at = |t: f64| (&sp.at * t).exp() * &y0;
                let row = |n: usize, y: &DVector<f64>| -> f64 {
                    (0..dim).map(|j| sp.rows[(n, j)] * y[j]).sum()
                };
                let (amp, om) = (fr.wp[1] + base_amp(&p), p.omega);
                let exact = |t: f64| -> (f64, f64) {
                    let y = y_at(t);
                    let (s, c) = (om * (tau0 + t)).sin_cos();
                    let v = row(0, &y) + fr.wp[0] + p.alpha5 + amp * s + fr.wp[2] * c;
                    let dv = row(1, &y) + om * (amp * c - fr.wp[2] * s);
                    let sigma = r.guard_sign();
                    (sigma * v + prop.dead, sigma * dv)
                };
                // W_hom = c̃ᵀy and its derivatives c̃ᵀÃy, c̃ᵀÃ²y, plus W_p = wp·(1, sin, cos)
                let tip_exact = |t: f64| -> [f64; 3] {
                    let y = y_at(t);
                    let (s, c) = (om * (tau0 + t)).sin_cos();
                    let (w0, ws, wc) = (fr.wp[0], fr.wp[1], fr.wp[2]);
                    [
                        row(0, &y) + w0 + ws * s + wc * c,
                        row(1, &y) + om * (ws * c - wc * s),
                        row(2, &y) - om * om * (ws * s + wc * c),
                    ]
                };
                let y_mid = y_at(0.5 * h);
                let mut q_mid = Modes::ZERO;
                me.project(y_mid.as_slice(), &mut q_mid);
                let scale = sp.ct_norm * y0.norm() * (1.0 + sp.rho)
                    + fr.wp.iter().map(|w| w.abs()).sum::<f64>()
                    + amp.abs() * (1.0 + om);
                let starts = [
                    (0.0, SeriesStart::Energy(y0.as_slice())),
                    (0.5 * h, SeriesStart::Energy(y_mid.as_slice())),
                    (0.5 * h, SeriesStart::Modal(me, &q_mid)),
                ];
                for (case, (center, start)) in starts.into_iter().enumerate() {
                    let mut poly = TipPoly::empty();
                    ExactPropagator::build_poly(
                        sp,
                        fr,
                        &p,
                        prop.dead,
                        r,
                        (tau0, center, (om * (tau0 + center)).sin_cos()),
                        start,
                        h,
                        &mut poly,
                    );
                    assert_eq!(poly.center, center);
                    for k in 0..=40 {
                        let t = h * k as f64 / 40.0;
                        let (g, dg) = poly.g(t);
                        let (ge, dge) = exact(t);
                        let at = format!("N = {modes}, {r:?}, start {case}, t = {t}");
                        assert!((g - ge).abs() <= 1e-13 * scale, "{at}: g {g} vs {ge}");
                        assert!((dg - dge).abs() <= 1e-12 * scale, "{at}: g' {dg} vs {dge}");
                        // the dense tip deflection [W, W', W''] (eq. 9 at ξ = 1, with the
                        // particular part W_p), W'' against c̃ᵀÃ²y
                        let w = poly.w(t);
                        let we = tip_exact(t);
                        for (d, tol) in [(0, 1e-13), (1, 1e-12), (2, 1e-11 * (1.0 + sp.rho))] {
                            let (a, b) = (w[d], we[d]);
                            assert!((a - b).abs() <= tol * scale, "{at}: W^({d}) {a} vs {b}");
                        }
                    }
                }
            }
        }
    }

    /// The cached forcing data (particular solution, grid tables) belong to the parameters that
    /// made them: a build that differs only in the gap α5 — with no contact stiffness or damping,
    /// so that no region's forcing vector sees α5 — gets V_T on the grid of its own α5, as a
    /// build without reuse does.
    #[test]
    fn forcing_cache_tells_gaps_apart() {
        let p = Params {
            alpha4: 0.0,
            alpha6: 0.0,
            alpha5: 0.3,
            ..Params::default()
        };
        let q = Params { alpha5: 0.7, ..p };
        let (mp, mq) = (
            CantileverModel::new(&p).unwrap(),
            CantileverModel::new(&q).unwrap(),
        );
        let _cached = ExactPropagator::try_new(&mp, 1).unwrap();
        let reused = ExactPropagator::try_new(&mq, 1).unwrap();
        let fresh = ExactPropagator::try_with(
            &mq,
            ExactOptions {
                reuse: false,
                ..ExactOptions::default()
            },
        )
        .unwrap();
        for ri in 0..2 {
            assert_eq!(
                reused.forced[ri].vp_grid, fresh.forced[ri].vp_grid,
                "region {ri}"
            );
        }
    }
}

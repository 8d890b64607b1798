//! Runs of whole grid steps between switchings ([`ExactPropagator`]'s `grid_run`): the
//! certified test of [`RunLimits`] over the dense ([`DenseSteps`]) or the modal
//! ([`ModalSteps`]) path, without the per-step bookkeeping of `step_impl`.

use super::bound::StepGuard;
use super::forcing::{grid_v_t, Forced};
use super::modal::{ModalExp, Modes};
use super::search::StepEnds;
use super::tip::tip_v_t;
use super::ExactPropagator;
use crate::error::SimError;
use crate::integrate::grid::PeriodGrid;
use crate::linalg::kernel::MatVec;
use crate::model::CantileverModel;
use nalgebra::DVector;

/// One whole dense grid step k → k + 1: δz = z − z_p(τ_k) into `dz`,
/// y = z_p(τ_{k+1}) + Φ_s δz into `y` (`phi`: Φ_s column-major with its kernel), and
/// [V_T, dV_T/dτ] at τ_{k+1} (eq. 8), given `trig` = (sin Ωτ_{k+1}, cos Ωτ_{k+1}). Slices of
/// length 2N.
#[inline(always)]
pub(super) fn dense_grid_step(
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
    /// Take the step tried last (its start is kept as the start of the last step), which ends
    /// at grid point `k_next` (sub-step index); returns whether the run may go on after it
    /// (false where a span's body-contact guard does not spare its end, `span.rs`).
    fn accept(&mut self, k_next: usize) -> bool;
}

/// How a run of grid steps ended ([`RunLimits::run`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum RunEnd {
    /// Before a step that would end off the grid or beyond the end time, or that fails the
    /// certified test.
    Stopped,
    /// At the end of a period.
    PeriodEnd,
    /// After a step whose end the span's guard does not spare (at a period end too: `bool`).
    Guard(bool),
}

impl RunLimits {
    /// Whole grid steps from grid point `at` at (τ, (V_T, dV_T/dτ)) = (`tau`, `vt`), each taken
    /// when it ends by `tau_end` and passes the certified test, up to the end of the current
    /// period (`trig`: sin/cos Ωτ on the grid of one period); the step loop of `step_impl` for
    /// these steps, with the same t_grid ([`PeriodGrid::tau`]) and test. Returns the start time
    /// of the last step taken (`None`: none) and how the run ended.
    fn run(
        &self,
        trig: &[(f64, f64)],
        tau: &mut f64,
        vt: &mut (f64, f64),
        at: &mut (i64, usize),
        steps: &mut impl GridSteps,
    ) -> (Option<f64>, RunEnd) {
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
                return (tau_last, RunEnd::Stopped);
            }
            let vt_b = steps.try_step(k, trig[k + 1]);
            if !StepEnds::new(self.sigma, self.dead, *vt, vt_b, false).certified(self.curv, len) {
                return (tau_last, RunEnd::Stopped);
            }
            let go_on = steps.accept(next.1);
            tau_last = Some(*tau);
            *tau = t_grid;
            *vt = vt_b;
            *at = next;
            if !go_on {
                return (tau_last, RunEnd::Guard(next.1 == 0));
            }
            if next.1 == 0 {
                return (tau_last, RunEnd::PeriodEnd);
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
    fn accept(&mut self, _k_next: usize) -> bool {
        std::mem::swap(self.z, self.zb);
        std::mem::swap(self.dz_try, self.dz_last);
        true
    }
}

/// Modal whole grid steps ([`ModalExp::advance_into`] with e^{Λh}): on acceptance the
/// propagator's three boxed buffers trade places (prev ← cur ← tried ← prev, by pointer), so
/// that after a run q holds the current modal coordinates, `last.q0` the start of the last
/// step and the scratch the free one, without copies; with a span's body-contact guard
/// ([`StepGuard`]) the run stops after a step whose end it does not spare.
struct ModalSteps<'a, G> {
    me: &'a ModalExp,
    fr: &'a Forced,
    cur: &'a mut Box<Modes>,
    tried: &'a mut Box<Modes>,
    prev: &'a mut Box<Modes>,
    guard: G,
}

impl<'a> ModalSteps<'a, ()> {
    /// The same steps with a span's guard.
    fn with_guard<G: Guard>(self, guard: G) -> ModalSteps<'a, G> {
        let ModalSteps {
            me,
            fr,
            cur,
            tried,
            prev,
            ..
        } = self;
        ModalSteps {
            me,
            fr,
            cur,
            tried,
            prev,
            guard,
        }
    }
}

/// The guard of a run's steps: none (`()`, every step spared) or a span's [`StepGuard`].
trait Guard {
    /// Whether the step ending at grid point `k` with modal coordinates `q` is spared.
    fn spared(&self, k: usize, q: &Modes) -> bool;
}

impl Guard for () {
    #[inline(always)]
    fn spared(&self, _k: usize, _q: &Modes) -> bool {
        true
    }
}

impl Guard for StepGuard<'_> {
    #[inline(always)]
    fn spared(&self, k: usize, q: &Modes) -> bool {
        StepGuard::spared(self, k, q)
    }
}

impl<G: Guard> GridSteps for ModalSteps<'_, G> {
    fn try_step(&mut self, k: usize, _trig: (f64, f64)) -> (f64, f64) {
        let tip = self
            .me
            .advance_into(self.cur, &self.fr.grid_fac, self.tried);
        grid_v_t(self.fr, k + 1, tip)
    }
    fn accept(&mut self, k_next: usize) -> bool {
        std::mem::swap(self.prev, self.cur);
        std::mem::swap(self.cur, self.tried);
        self.guard.spared(k_next, self.cur)
    }
}

impl ExactPropagator {
    /// Whole grid steps from the current grid point, as long as each ends by `tau_end` and
    /// passes the certified test — the common case between switchings — exactly as
    /// [`Self::step_impl`] with [`Form::Nothing`] takes them (the same operations in the same
    /// order, so bit for bit the same states, V_T and last step), without its per-step
    /// bookkeeping. Stops before a step that would end off the grid or beyond `tau_end`, or
    /// that fails the test (`step_impl` then takes it, with the search), and right after a
    /// switching or [`Integrator::reset`]. At each period end the plain state is formed and
    /// checked as `step_impl` does ([`Self::check_divergence`]).
    ///
    /// [`Form::Nothing`]: super::step::Form::Nothing
    /// [`Integrator::reset`]: crate::integrate::Integrator::reset
    pub(super) fn grid_run(&mut self, tau_end: f64) -> Result<(), SimError> {
        if self.just_switched {
            return Ok(());
        }
        let ri = self.region.index();
        let modal = self.modal[ri] && self.spec[ri].modal.is_some();
        loop {
            let end = if modal {
                self.modal_run(tau_end)
            } else {
                self.dense_run(tau_end)
            };
            if let RunEnd::Guard(_) = end {
                self.guard_stopped = true;
            }
            if let RunEnd::PeriodEnd | RunEnd::Guard(true) = end {
                self.check_divergence()?;
            }
            if end != RunEnd::PeriodEnd {
                return Ok(());
            }
        }
    }

    /// [`Self::grid_run`] in a dense region: z ← z_p(τ_{k+1}) + Φ_s (z − z_p(τ_k)). Returns
    /// how it ended.
    fn dense_run(&mut self, tau_end: f64) -> RunEnd {
        let Some(mut at) = self.on_grid else {
            return RunEnd::Stopped;
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
        let (ran, end) = limits.run(trig, tau, vt, &mut at, &mut steps);
        let Some(tau0) = ran else {
            return RunEnd::Stopped;
        };
        self.finish_run(tau0, at, false);
        end
    }

    /// [`Self::grid_run`] in a modal region: q ← e^{Λh} ⊙ q, the plain state not formed (as
    /// `step_impl` with [`Form::Nothing`]); inside a span with a body-contact guard
    /// (`span.rs`), up to the first step whose end the guard does not spare. Returns how it
    /// ended.
    ///
    /// [`Form::Nothing`]: super::step::Form::Nothing
    fn modal_run(&mut self, tau_end: f64) -> RunEnd {
        let Some(mut at) = self.on_grid else {
            return RunEnd::Stopped;
        };
        let limits = self.run_limits(tau_end);
        let ExactPropagator {
            ref bound_cols,
            span_guard,
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
            return RunEnd::Stopped;
        };
        let mut steps = ModalSteps {
            me,
            fr,
            cur: q,
            tried: scratch,
            prev: &mut last.q0,
            guard: (),
        };
        // (the step loop without a guard for the runs outside a span: no test per step)
        let (ran, end) = match span_guard.map(|stint| bound_cols.guard(ri, stint)) {
            None => limits.run(trig, tau, vt, &mut at, &mut steps),
            Some(g) => limits.run(trig, tau, vt, &mut at, &mut steps.with_guard(g)),
        };
        let Some(tau0) = ran else {
            return RunEnd::Stopped;
        };
        // (the runs of `advance_to` keep no tip: nobody reads it there)
        self.tip_hom = None;
        self.finish_run(tau0, at, true);
        end
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
        self.last.span = false;
        self.last.modal = modal;
        self.last.k = at.1.checked_sub(1).unwrap_or(self.grid.m - 1);
        self.on_grid = Some(at);
        self.poly_built = false;
        // z lags behind q after modal steps (formed by materialize)
        self.stale = modal;
    }
}

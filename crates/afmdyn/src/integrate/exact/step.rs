//! One step of the exact propagator (`step_impl`): a whole grid step or a partial one, the
//! certified switching test, and where it fails the search for the leftmost switching.

use super::forcing::{grid_v_t, modal_v_t};
use super::modal::ModalExp;
use super::run::dense_grid_step;
use super::search::{Search, StepEnds};
use super::series::SeriesAt;
use super::tip::tip_v_t;
use super::ExactPropagator;
use crate::error::SimError;
use crate::integrate::Step;

/// What [`ExactPropagator::step_impl`] forms besides the propagation itself.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Form {
    /// The plain state after every step and the record of an event ([`Integrator::step`]).
    ///
    /// [`Integrator::step`]: crate::integrate::Integrator::step
    All,
    /// The record of an event; after a step in a modal region the plain state lags behind q
    /// ([`Integrator::step_deferred`]).
    ///
    /// [`Integrator::step_deferred`]: crate::integrate::Integrator::step_deferred
    Events,
    /// Neither (inside [`Spans::advance_to`] and the batch, which read only the result's
    /// `Ok`/`Err`).
    ///
    /// [`Spans::advance_to`]: crate::integrate::Spans::advance_to
    Nothing,
}

impl ExactPropagator {
    /// One step (see [`Integrator::step`]), forming what `form` asks for: with
    /// [`Form::Events`] and [`Form::Nothing`] the plain state at the end of a step in a modal
    /// region is not formed (z lags behind q), and with [`Form::Nothing`] a switching is
    /// returned without its event record (no copy of the state).
    ///
    /// [`Integrator::step`]: crate::integrate::Integrator::step
    pub(super) fn step_impl(&mut self, tau_max: f64, form: Form) -> Result<Step, SimError> {
        let region = self.region;
        let tau0 = self.tau;
        let next = self.next_grid_point(tau0);
        // as PeriodGrid::tau
        let t_grid = next.0 as f64 * self.grid.period + next.1 as f64 * self.grid.h;
        // a target a few ulps short of the grid point (a sample time start + k·T/S rounded
        // apart from the grid's p·T + k·h) ends the step on the grid point: the step stays a
        // whole one (its tables), not a partial one plus a step of an ulp
        let snap = tau_max < t_grid && t_grid - tau_max <= 4.0 * f64::EPSILON * t_grid.abs();
        let tau_b = if snap { t_grid } else { t_grid.min(tau_max) };
        let len = tau_b - tau0;
        if len <= 0.0 {
            return Ok(Step::plain(tau0, tau0, region));
        }
        let full = self.on_grid.is_some() && tau_b == t_grid;
        // this step ends by t_grid, and until t_grid the next grid point stays `next`
        self.between = Some((next, t_grid));
        self.poly_built = false;
        self.last.tau0 = tau0;
        self.last.region = region;
        self.last.full = full;
        self.last.span = false;
        self.last.modal = self.modal[region.index()];
        self.last.k = self.on_grid.map_or(0, |(_, k)| k);
        let (vt_b, end_state) = self.propagate(tau0, tau_b, (next, t_grid), full, form);
        let hit = self.first_switching(tau0, len, vt_b);
        self.just_switched = false;
        let Some(t) = hit else {
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
            return Ok(Step::plain(tau0, tau_b, region));
        };
        self.switch_at(tau0 + t, t)?;
        if form == Form::Nothing {
            return Ok(Step::plain(tau0, self.tau, region));
        }
        Ok(Step::switched(&self.model, tau0, region, self.tau, &self.z))
    }

    /// The grid point (period, column) after τ0: the next of the one the state is on, the one
    /// a step between grid points was headed to (while τ0 is short of it), else the grid's
    /// next index.
    #[inline(always)]
    fn next_grid_point(&self, tau0: f64) -> (i64, usize) {
        let m = self.grid.m;
        match self.on_grid {
            Some((p, k)) if k + 1 < m => (p, k + 1),
            Some((p, _)) => (p + 1, 0),
            None => match self.between {
                Some((next, t_next)) if tau0 < t_next => next,
                _ => {
                    let j = self.grid.next_index(tau0);
                    (j.div_euclid(m as i64), j.rem_euclid(m as i64) as usize)
                }
            },
        }
    }

    /// The propagation from τ0 to τ_b (the grid point `next` at `t_grid`, reached by a whole
    /// grid step when `full`): the end's state into q (a modal region) or zb, its tip's V_T and
    /// rate, and whether the plain state at the end was formed (in a modal region only when `form`
    /// is [`Form::All`]).
    #[inline(always)]
    fn propagate(
        &mut self,
        tau0: f64,
        tau_b: f64,
        (next, t_grid): ((i64, usize), f64),
        full: bool,
        form: Form,
    ) -> ((f64, f64), bool) {
        let omega = self.model.omega();
        let len = tau_b - tau0;
        let k = self.last.k;
        let ri = self.region.index();
        let dim = self.z.len();
        let fr = &self.forced[ri];
        // sin, cos Ωτ_b: from the grid's table when the step ends on a grid point (column k, or
        // m at a period end, as a whole grid step to it and `materialize` take them)
        let trig_b = if tau_b == t_grid {
            self.trig[self.grid.table_column(next.1)]
        } else {
            (omega * tau_b).sin_cos()
        };
        match (&self.spec[ri].modal, self.modal[ri]) {
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
                let end_state = form == Form::All;
                if end_state {
                    let zb = self.zb.as_mut_slice();
                    if full {
                        zb.copy_from_slice(&fr.zp_grid.as_slice()[(k + 1) * dim..(k + 2) * dim]);
                    } else {
                        Self::zp_at(fr, trig_b, zb);
                    }
                    ModalExp::expand(&me.tv, &self.q, zb, true);
                }
                let vt_b = if full {
                    grid_v_t(fr, k + 1, (w, wd))
                } else {
                    modal_v_t(&self.model, fr, (w, wd), trig_b)
                };
                (vt_b, end_state)
            }
            _ if full => {
                let vt_b = dense_grid_step(
                    &self.model,
                    fr,
                    (self.phi[ri].as_slice(), self.kernel),
                    (k, self.trig[k + 1]),
                    self.z.as_slice(),
                    self.last.dz0.as_mut_slice(),
                    self.zb.as_mut_slice(),
                );
                (vt_b, true)
            }
            _ => {
                // sin, cos at τ0 (kept from a switching or reset there); at τ_b once (τ0 + len
                // is τ_b but for rounding, when τ_b > 2τ0)
                let sc0 = self.trig_at(tau0);
                let dz0 = self.last.dz0.as_mut_slice();
                Self::zp_at(fr, sc0, dz0);
                for (d, z) in dz0.iter_mut().zip(self.z.as_slice()) {
                    *d = z - *d;
                }
                let sc_end = if tau0 + len == tau_b {
                    trig_b
                } else {
                    (omega * (tau0 + len)).sin_cos()
                };
                let mut zb = std::mem::take(&mut self.zb);
                self.state_in_last_at(len, sc_end, zb.as_mut_slice());
                let v = tip_v_t(&self.model, zb.as_slice(), trig_b);
                self.zb = zb;
                (v, true)
            }
        }
    }

    /// The time after τ0 of the leftmost switching in the step of `len` that ends at (V_T, its
    /// rate) = `vt_b`; `None` where the ends' certified test rules one out or the search finds
    /// none.
    #[inline(always)]
    fn first_switching(&mut self, tau0: f64, len: f64, vt_b: (f64, f64)) -> Option<f64> {
        let ri = self.region.index();
        let ends = StepEnds::new(
            self.region.guard_sign(),
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
        if ends.certified(cheap, len) {
            return None;
        }
        self.build_last_series(len, SeriesAt::Centred);
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
            Some(a)
        } else {
            search.first(a, g_a, len, (gb, db), 0)
        }
    }

    /// The switching at τ_s = τ0 + `t` into the other region: the state there (from the last
    /// step's start), its V_T, and the other region's stint entered.
    ///
    /// # Errors
    /// As the chatter record ([`SimError`] for a chattering switching sequence).
    #[inline(always)]
    fn switch_at(&mut self, tau_s: f64, t: f64) -> Result<(), SimError> {
        let region = self.region;
        let ri = region.index();
        let sc = (self.model.omega() * tau_s).sin_cos();
        let mut zs = std::mem::take(&mut self.z);
        match (&self.spec[ri].modal, self.modal[ri]) {
            // the state_in_last_at of a modal step, keeping q0 e^{Λt} (the same
            // products and sums, so the same state)
            (Some(me), true) => {
                let qs = &mut self.q_switch;
                me.factors(t, qs);
                qs.mul_assign(&self.last.q0, me.len());
                Self::zp_at(&self.forced[ri], sc, zs.as_mut_slice());
                ModalExp::expand(&me.tv, qs, zs.as_mut_slice(), true);
            }
            _ => self.state_in_last_at(t, sc, zs.as_mut_slice()),
        }
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
        self.chatter.record(tau_s)
    }
}

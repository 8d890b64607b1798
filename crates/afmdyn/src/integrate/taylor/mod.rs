//! The Taylor integrator: a high-order Taylor series method for the cantilever with a nonlinear
//! tip force (Hertz, DMT), the free flight in τ and the contact in a regularising time σ
//! (dτ = 2√δ dσ) in which the δ^{3/2} force is a polynomial (`jet.rs`).
//!
//! One step forms the Taylor coefficients of the state (and, with
//! [`Integrator::set_variational`], of the step's Jacobian Φ = ∂z(τ)/∂z(τ₀)) to order
//! p = ⌈¾ ln(1/ε) + 1⌉ (22 at the default tolerance ε = 1e-12; `poly::order_for`) by the
//! recurrences of automatic differentiation, then takes the step h = ρ ε^{1/p} e^{−0.7/(p−1)}
//! from the radius of convergence ρ the last two orders show (Jorba & Zou, *Exp. Math.* 14
//! (2005) 99; `poly::step_size`), so that the truncation error is about ε relative to
//! max(1, ‖z‖). A step is never rejected: the coefficients are formed once.
//!
//! **Why σ in contact.** With δ ≈ v (τ − τ_c) the Hertz force makes the solution
//! non-analytic at both ends of a contact, and any method in τ takes geometrically shrinking
//! steps there (the adaptive DOP853 takes 23 steps through a contact of the point-mass DMT
//! probe, 20 of them in the onset and release). In σ, w = √δ and τ are state variables and the
//! field is polynomial: a contact of the point-mass DMT probe takes 5 steps and ends at a
//! simple zero of w.
//!
//! **The contact's interior** is integrated in τ (`Interior`): in σ every equation is
//! multiplied by τ′ = 2w, so each order of the series takes a product of series per state
//! component (O(N p²) a step), while in τ the modal equations keep the free flight's linear
//! recurrence and only w = √δ (from w² = δ) and the force need products. Where δ is bounded
//! away from 0 the τ series converges (its radius is the distance to the complex time where
//! δ = 0), so after the first σ steps of a contact a τ step is tried, taken when it advances at
//! least as far as the last σ step and δ stays positive over it, and the contact returns to σ
//! for good once a τ step is refused past the deepest point (or the deepest point is passed
//! without one). On the default beam (N = 3, Hertz) a contact takes 4 σ steps, 10 τ steps
//! and 4 σ steps: 234.5 M → 152.4 M instructions over 450 periods (`period_cost hertz 3 200`),
//! DMT 219.6 M → 169.6 M; the point mass, whose 5 σ steps per contact are long, keeps them
//! (its contact's τ steps are no longer: 728.2 M → 728.6 M for the probe).
//!
//! **Events** are zeros of the guard's Taylor polynomial — V_T in free flight, w in contact —
//! located by safeguarded Newton on the polynomial itself (`poly::leftmost_crossing`; the
//! polynomial is the solution to the tolerance, so no step is integrated again), with two
//! certified bounds that spare the search in most steps and a scan that finds grazing dips.
//! The state at the event comes from the series. The laws' switchings are plain (the force is
//! continuous for DMT; Hertz's damper jumps), so the analyses apply the saltation matrix of
//! [`crate::system`] as for every integrator.
//!
//! **Dense output** is the series: at s = τ − τ₀ in free flight and in the contact's
//! interior, in a σ step at the σ with τ₀ + θ(σ) = τ (θ increases, θ′ = 2w > 0 inside the
//! contact; safeguarded Newton).
//!
//! Supported laws: Hertz and DMT ([`Taylor::new`] refuses the linear law, which the exact
//! propagator integrates, and the impact law, whose contact is a constraint).

mod jet;
pub(crate) mod poly;

use super::{ChatterWindow, Integrator, SmoothTime, Step, StepBudget};
use crate::error::SimError;
use crate::model::CantileverModel;
use crate::roots::safeguarded_newton;
use crate::system::{HybridSystem, Region};
use crate::tip_sample::TipSampleSystem;
use jet::{Jet, Order, Series};
use nalgebra::{DMatrix, DVector};

/// Events within this many drive periods' ten-millionth that count as chattering (as the
/// adaptive integrator).
const CHATTER_COUNT: usize = 4096;

/// The last step: its series (the dense output), its span and its Jacobian.
#[derive(Debug, Clone)]
struct LastStep {
    tau0: f64,
    tau1: f64,
    region: Region,
    /// The step's end in the series' variable (τ − τ₀ in free flight, σ in contact).
    end: f64,
    /// Whether `series` belongs to a step taken since the last restart.
    valid: bool,
    series: Box<Series>,
    /// ∂z(τ1)/∂z(τ0) when the variational equations were on.
    jacobian: Option<DMatrix<f64>>,
}

/// The Taylor integrator of a [`CantileverModel`] with the Hertz or DMT law (module docs).
#[derive(Debug, Clone)]
pub struct Taylor {
    model: CantileverModel,
    /// The shortest drive period 2π/max(Ω, ω_c) (a multifrequency drive's fastest component
    /// included): a free step spans at most a quarter of it ([`rule`]).
    drive_period: f64,
    jet: Jet,
    tol: f64,
    order: usize,
    tau: f64,
    z: DVector<f64>,
    region: Region,
    variational: bool,
    /// The state sits on the guard's zero after an event (the zero at the step's start does
    /// not count).
    just_switched: bool,
    chatter: ChatterWindow,
    budget: StepBudget,
    /// The series of the step being formed (it trades places with the last step's).
    next: Box<Series>,
    last: LastStep,
    /// The last piece [a, b] of [`Integrator::smooth_time`] and its ends σ(a), σ(b).
    smooth_piece: Option<(f64, f64, f64, f64)>,
    /// Where the current contact stands between its σ and its τ steps (module docs).
    interior: Interior,
}

/// The choice between a contact step in σ and one in τ (module docs, "The contact's
/// interior"): a τ step is tried while `open` once the contact is [`INTERIOR_DEPTH`] σ steps'
/// advances old (from `entry`), and taken when it advances at least as far as the last σ step
/// (`advance`) and δ stays positive over it.
#[derive(Debug, Clone, Copy)]
struct Interior {
    open: bool,
    taken: bool,
    entry: f64,
    advance: f64,
}

impl Interior {
    /// A contact entered (or the integrator restarted) at τ = `entry`.
    fn start(entry: f64) -> Self {
        Interior {
            open: true,
            taken: false,
            entry,
            advance: f64::INFINITY,
        }
    }
}

/// How many of its σ steps' advances (in τ) from the contact's entry a τ step is first tried:
/// the τ series' radius is about the distance to the entry, where δ = 0 (a branch point of
/// √δ), and the step about a third of the radius (the step rule at p = 22: ρ ε^{1/p} e^{−0.7/(p−1)}
/// = 0.28 ρ); measured on the default beam (N = 3, Hertz): the first τ step that advances as
/// far as the σ steps comes 2.9 σ advances after the entry, the tries at 2.1 and earlier are
/// refused.
const INTERIOR_DEPTH: f64 = 2.5;

impl Taylor {
    /// The Taylor integrator of `model` with tolerance `tol` (relative to max(1, ‖z‖)); start
    /// with [`Integrator::reset`].
    ///
    /// # Errors
    /// [`SimError::Unsupported`] for the linear law (use the exact propagator) and the impact
    /// law (a constraint in contact: the split or adaptive integrator);
    /// [`SimError::OutOfRange`] for a tolerance outside (0, 1).
    pub fn new(model: &CantileverModel, tol: f64) -> Result<Self, SimError> {
        if !(tol.is_finite() && tol > 0.0 && tol < 1.0) {
            return Err(SimError::out_of_range(
                "tolerance",
                tol,
                "must be in (0, 1)",
            ));
        }
        let Some(jet) = Jet::new(model) else {
            return Err(SimError::Unsupported {
                integrator: "taylor",
                law: model.law().name(),
                hint: model.law().taylor_hint(),
            });
        };
        let d = model.dim();
        let p = model.params();
        let fastest = p
            .components()
            .fold(p.omega, |m, c| m.max(c.ratio() * p.omega));
        Ok(Taylor {
            drive_period: std::f64::consts::TAU / fastest,
            jet,
            tol,
            order: poly::order_for(tol),
            tau: 0.0,
            z: DVector::zeros(d),
            region: Region::Free,
            variational: false,
            just_switched: true,
            chatter: ChatterWindow::new(CHATTER_COUNT, 1e-7 * model.period()),
            budget: StepBudget::new("taylor integrator", model.period()),
            next: Box::default(),
            last: LastStep {
                tau0: 0.0,
                tau1: 0.0,
                region: Region::Free,
                end: 0.0,
                valid: false,
                series: Box::default(),
                jacobian: None,
            },
            smooth_piece: None,
            interior: Interior::start(0.0),
            model: model.clone(),
        })
    }

    /// The tolerance.
    pub fn tolerance(&self) -> f64 {
        self.tol
    }

    /// Restart at (τ, z) in `region` without checking z (the caller did), keeping the
    /// chattering test and the step budget of the drive period (a hand-over from the exact free
    /// flight of [`super::split::Split`], or an event's new region).
    pub(crate) fn restart_in(&mut self, tau: f64, z: &[f64], region: Region) {
        self.tau = tau;
        self.z.as_mut_slice().copy_from_slice(z);
        self.region = region;
        self.just_switched = true;
        self.last.valid = false;
        self.smooth_piece = None;
        self.last.jacobian = None;
        self.last.tau0 = tau;
        self.last.tau1 = tau;
        self.last.region = region;
        self.interior = Interior::start(tau);
    }

    /// Forget the events and steps counted so far (a new run).
    pub(crate) fn forget_events(&mut self) {
        self.chatter.clear();
        self.budget.forget();
    }

    /// σ in [0, `hi`] with θ(σ) = `target` (0 < target ≤ θ(hi)): θ increases there.
    fn sigma_at(theta: &[f64], target: f64, hi: f64) -> f64 {
        let g_hi = target - poly::eval(theta, hi);
        if g_hi >= 0.0 {
            return hi;
        }
        safeguarded_newton(0.0, target, hi, g_hi, 0.0, &mut |s| {
            let [v, dv, _] = poly::eval3(theta, s);
            (target - v, -dv)
        })
    }

    /// The series variable of τ inside the last step.
    fn local(&self, tau: f64) -> f64 {
        let l = &self.last;
        let tau = tau.clamp(l.tau0, l.tau1);
        match l.series.sigma {
            false => tau - l.tau0,
            true => {
                let s = &l.series;
                let target = tau - l.tau0;
                if target <= 0.0 {
                    0.0
                } else if tau >= l.tau1 {
                    l.end
                } else {
                    Self::sigma_at(&s.theta[..=s.p], target, l.end)
                }
            }
        }
    }
}

/// The step the rule allows for the series in `s` (in its own variable), at most a quarter of
/// the drive `period` in free flight: where the motion is small against 1 (a transient from
/// rest) the rule's error, ε relative to max(1, ‖z‖), allows steps of 40 % of a period, over
/// which the energy balance's products of series lose their relative accuracy (1.7e-8 of the
/// point-mass probe's balance from rest; 1.1e-11 with the cap, which does not bind on its
/// orbit).
fn rule(s: &Series, period: f64, tol: f64) -> f64 {
    let p = s.p;
    let x0 = s.order_norm(0);
    let h = poly::step_size(x0, s.order_norm(p - 1), s.order_norm(p), p, tol);
    match s.region {
        Region::Free => h.min(period / 4.0),
        Region::Contact if h.is_finite() => h,
        // a contact series vanishing beyond order 0 (not met: w′ = δ̇ ≠ 0 at the onset)
        Region::Contact => 1.0,
    }
}

/// The step's Jacobian at its end `end` (the series' variable) into `jacobian` (d × d, its
/// storage reused), or `None` without the variational equations.
#[inline]
fn keep_jacobian(
    jacobian: &mut Option<DMatrix<f64>>,
    s: &Series,
    end: f64,
    d: usize,
    variational: bool,
) {
    if !variational {
        *jacobian = None;
        return;
    }
    let m = match jacobian {
        Some(m) if m.nrows() == d && m.ncols() == d => m,
        _ => jacobian.insert(DMatrix::zeros(d, d)),
    };
    s.jacobian_at(end, m.as_mut_slice());
}

impl Integrator for Taylor {
    current_fields!();
    variational_fields!("taylor");
    fn set_gap(&mut self, alpha5: f64) -> bool {
        if self.model.set_gap(alpha5).is_err() {
            return false;
        }
        self.jet.set_gap(alpha5);
        true
    }

    fn step(&mut self, tau_max: f64) -> Result<Step, SimError> {
        let tau0 = self.tau;
        let region = self.region;
        if tau_max <= tau0 {
            return Ok(Step::plain(tau0, tau0, region));
        }
        self.budget.count(tau0)?;
        let order = Order {
            p: self.order,
            variational: self.variational,
        };
        let remaining = tau_max - tau0;
        let dead = self.model.guard_tolerance(region, tau0, self.z.as_slice());
        let s = &mut *self.next;
        // (end in the series' variable, end time, whether a guard zero ends the step)
        let (end, tau1, hit) = match region {
            Region::Free => {
                self.jet.free(s, tau0, self.z.as_slice(), order);
                let h = rule(s, self.drive_period, self.tol).min(remaining);
                let hit = poly::leftmost_crossing(s.guard(), h, dead, self.just_switched);
                match hit {
                    Some(e) => (e, tau0 + e, true),
                    None if h >= remaining => (h, tau_max, false),
                    None => (h, tau0 + h, false),
                }
            }
            Region::Contact => 'contact: {
                // V_T and dV_T/dτ from one sin/cos of Ωτ₀
                let [_, _, v, v_dot] = self.model.tip_values(tau0, &self.z);
                let w0 = (-v).max(0.0).sqrt();
                let it = &mut self.interior;
                if it.open && !it.taken && v_dot >= 0.0 {
                    // past the deepest point without a τ step: σ to the contact's end
                    it.open = false;
                }
                if it.open && w0 > 0.0 && tau0 - it.entry >= INTERIOR_DEPTH * it.advance {
                    // the contact's interior in τ (module docs)
                    self.jet
                        .contact_interior(s, tau0, self.z.as_slice(), w0, order);
                    let h = rule(s, self.drive_period, self.tol);
                    if h >= it.advance
                        && poly::leftmost_crossing(s.depth(), h.min(remaining), 0.0, false)
                            .is_none()
                    {
                        it.taken = true;
                        break 'contact if h >= remaining {
                            (remaining, tau_max, false)
                        } else {
                            (h, tau0 + h, false)
                        };
                    }
                    // refused past the deepest point: σ to the contact's end
                    if s.depth()[1] <= 0.0 {
                        it.open = false;
                    }
                }
                self.jet.contact(s, tau0, self.z.as_slice(), w0, order);
                let h = rule(s, self.drive_period, self.tol);
                let hit = poly::leftmost_crossing(s.guard(), h, dead, self.just_switched);
                let e = hit.unwrap_or(h);
                let theta = &s.theta[..=order.p];
                if poly::eval(theta, e) >= remaining {
                    (Self::sigma_at(theta, remaining, e), tau_max, false)
                } else {
                    // a whole σ step's advance (not one cut at τ_max): the yardstick of the τ
                    // steps
                    let advance = poly::eval(theta, e);
                    self.interior.advance = advance;
                    (e, tau0 + advance, hit.is_some())
                }
            }
        };
        self.just_switched = false;
        let d = self.z.len();
        let mut z1 = [0.0; 2 * crate::params::MAX_MODES];
        let z1 = &mut z1[..d];
        s.state_at(end, z1);
        let norm = z1.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm.is_nan() || norm >= crate::params::STATE_NORM_MAX {
            return Err(SimError::Diverged { tau: tau1, norm });
        }
        keep_jacobian(&mut self.last.jacobian, s, end, d, order.variational);
        // the step's series becomes the dense output
        std::mem::swap(&mut self.last.series, &mut self.next);
        self.last.tau0 = tau0;
        self.last.tau1 = tau1;
        self.last.region = region;
        self.last.end = end;
        self.last.valid = true;
        self.smooth_piece = None;
        if !hit {
            self.z.as_mut_slice().copy_from_slice(z1);
            self.tau = tau1;
            return Ok(Step::plain(tau0, tau1, region));
        }
        let z_minus = DVector::from_column_slice(z1);
        let jump = self.model.jump(region, tau1, z1);
        self.z.copy_from(&jump.state);
        self.tau = tau1;
        self.region = jump.to;
        self.just_switched = true;
        self.interior = Interior::start(tau1);
        self.chatter.record(tau1)?;
        Ok(Step::with_event(
            &self.model,
            tau0,
            region,
            tau1,
            &z_minus,
            jump.to,
            jump.kind,
        ))
    }

    fn dense_state(&mut self, tau: f64) -> DVector<f64> {
        let mut z = DVector::zeros(self.z.len());
        self.dense_state_into(tau, z.as_mut_slice());
        z
    }

    fn dense_state_into(&mut self, tau: f64, out: &mut [f64]) {
        if !self.last.valid {
            out.copy_from_slice(self.z.as_slice());
            return;
        }
        let s = self.local(tau);
        self.last.series.state_at(s, out);
    }

    fn dense_tip(&mut self, tau: f64) -> [f64; 3] {
        let n = self.model.modes();
        let z = self.dense_state(tau);
        let region = if self.last.valid {
            self.last.region
        } else {
            self.region
        };
        let mut f = [0.0; 2 * crate::params::MAX_MODES];
        let f = &mut f[..2 * n];
        self.model.rhs_slice(region, tau, z.as_slice(), f);
        let tip = self.model.tip().as_slice();
        let dot = |x: &[f64]| tip.iter().zip(x).map(|(a, b)| a * b).sum::<f64>();
        [dot(&z.as_slice()[..n]), dot(&f[..n]), dot(&f[n..])]
    }

    /// The energy balance's rates integrated over the last step from its series, in closed form
    /// to the truncation of the series (`Jet::rate_integrals`).
    fn last_step_rate_integrals(&mut self) -> Option<[f64; 3]> {
        if !self.last.valid {
            return None;
        }
        Some(self.jet.rate_integrals(&self.last.series, self.last.end))
    }

    fn smooth_time(&mut self) -> Option<&mut dyn SmoothTime> {
        if self.last.valid && self.last.series.sigma {
            Some(self)
        } else {
            None
        }
    }
}

/// In contact the step is smooth in σ: τ(u) = τ₀ + θ(σ(u)), σ linear in u between σ(a) and
/// σ(b) ([`Integrator::smooth_time`] hands it out for the σ steps only).
impl SmoothTime for Taylor {
    fn tau_of(&mut self, a: f64, b: f64, u: f64) -> (f64, f64) {
        let (sa, sb) = match self.smooth_piece {
            Some((pa, pb, sa, sb)) if pa == a && pb == b => (sa, sb),
            _ => {
                let (sa, sb) = (self.local(a), self.local(b));
                self.smooth_piece = Some((a, b, sa, sb));
                (sa, sb)
            }
        };
        let l = &self.last;
        let sigma = sa + u * (sb - sa);
        let [theta, dtheta, _] = poly::eval3(&l.series.theta[..=l.series.p], sigma);
        (l.tau0 + theta, dtheta * (sb - sa))
    }
}

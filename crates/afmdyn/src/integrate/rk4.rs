//! Fixed-step classical Runge–Kutta (RK4), the paper's integrator (§2, after eq. 18).
//!
//! Two variants:
//! * `locate_events = true`: the region is fixed during a step; when V_T changes sign over a
//!   step, the switching time is found by a secant/bisection iteration on the RK4 step length
//!   from the step's start, the step is cut there and the region changes. Fourth order overall.
//! * `locate_events = false` (the paper's method, "rk4-naive"): the right-hand side picks the
//!   region from the sign of V_T at every stage, so a step can straddle the switching and
//!   overshoot the discontinuity; a switching is reported at the end of the step where the
//!   region changed.

use super::grid::PeriodGrid;
use super::{HermiteStep, Integrator, Step};
use crate::error::SimError;
use crate::model::CantileverModel;
use crate::system::Region;
use crate::tip_sample::TipSampleSystem;
use nalgebra::{DMatrix, DVector};

/// Fixed-step RK4 integrator of a [`TipSampleSystem`] `S` (the cantilever model by default) on a
/// grid of `steps` sub-steps per drive period.
#[derive(Debug, Clone)]
pub struct Rk4<S: TipSampleSystem + Clone = CantileverModel> {
    model: S,
    grid: PeriodGrid,
    locate: bool,
    tau: f64,
    z: DVector<f64>,
    region: Region,
    k: [DVector<f64>; 5],
    last: HermiteStep,
}

/// How the right-hand side picks its region.
#[derive(Clone, Copy)]
enum Mode {
    Fixed(Region),
    PerStage,
}

impl<S: TipSampleSystem + Clone> Rk4<S> {
    /// `steps` fixed steps per drive period; `locate_events` as in the module docs.
    pub(crate) fn new(model: &S, steps: usize, locate_events: bool) -> Self {
        let dim = model.dim();
        let z = DVector::zeros(dim);
        Rk4 {
            model: model.clone(),
            grid: PeriodGrid::new(model.period(), steps),
            locate: locate_events,
            tau: 0.0,
            z: z.clone(),
            region: Region::Free,
            k: [z.clone(), z.clone(), z.clone(), z.clone(), z.clone()],
            last: HermiteStep::new(model.dim()),
        }
    }

    fn rhs(model: &S, mode: Mode, tau: f64, z: &DVector<f64>, out: &mut DVector<f64>) {
        let r = match mode {
            Mode::Fixed(r) => r,
            Mode::PerStage => model.region_at(tau, z),
        };
        model.rhs(r, tau, z.as_slice(), out.as_mut_slice());
    }

    /// One RK4 step of length h from (τ, z) into `out`.
    fn rk4(
        model: &S,
        mode: Mode,
        tau: f64,
        z: &DVector<f64>,
        h: f64,
        k: &mut [DVector<f64>; 5],
        out: &mut DVector<f64>,
    ) {
        let [k1, k2, k3, k4, tmp] = k;
        Self::rhs(model, mode, tau, z, k1);
        tmp.copy_from(z);
        tmp.axpy(0.5 * h, k1, 1.0);
        Self::rhs(model, mode, tau + 0.5 * h, tmp, k2);
        tmp.copy_from(z);
        tmp.axpy(0.5 * h, k2, 1.0);
        Self::rhs(model, mode, tau + 0.5 * h, tmp, k3);
        tmp.copy_from(z);
        tmp.axpy(h, k3, 1.0);
        Self::rhs(model, mode, tau + h, tmp, k4);
        out.copy_from(z);
        out.axpy(h / 6.0, k1, 1.0);
        out.axpy(h / 3.0, k2, 1.0);
        out.axpy(h / 3.0, k3, 1.0);
        out.axpy(h / 6.0, k4, 1.0);
    }

    fn grid_next(&self, tau: f64) -> f64 {
        self.grid.next(tau)
    }
}

impl<S: TipSampleSystem + Clone + 'static> Integrator for Rk4<S> {
    current_fields!();
    fn name(&self) -> &'static str {
        if self.locate {
            "rk4"
        } else {
            "rk4-naive"
        }
    }

    fn reset_in(&mut self, tau: f64, z: &DVector<f64>, region: Region) -> Result<(), SimError> {
        self.model.check_time_state(tau, z)?;
        self.region = region;
        self.tau = tau;
        self.z.copy_from(z);
        Ok(())
    }

    fn step(&mut self, tau_max: f64) -> Result<Step, SimError> {
        let tau0 = self.tau;
        let tau_b = self.grid_next(tau0).min(tau_max);
        let len = tau_b - tau0;
        let region = self.region;
        let z0 = self.z.clone();
        if len <= 0.0 {
            return Ok(Step::plain(tau0, tau0, region));
        }
        let mut out = DVector::zeros(z0.len());
        if !self.locate {
            Self::rk4(
                &self.model,
                Mode::PerStage,
                tau0,
                &z0,
                len,
                &mut self.k,
                &mut out,
            );
            self.z = out;
            self.tau = tau_b;
            let after = self.model.region_at(tau_b, &self.z);
            self.last
                .record(&self.model, after, tau0, &z0, self.tau, &self.z);
            check_finite(tau_b, &self.z)?;
            if after != region {
                self.region = after;
                return Ok(Step::switched(&self.model, tau0, region, tau_b, &self.z));
            }
            return Ok(Step::plain(tau0, tau_b, region));
        }
        let mode = Mode::Fixed(region);
        let sigma = region.guard_sign();
        Self::rk4(&self.model, mode, tau0, &z0, len, &mut self.k, &mut out);
        let g = |m: &S, t: f64, z: &DVector<f64>| sigma * m.v_t(t, z);
        check_finite(tau_b, &out)?;
        let gb = g(&self.model, tau_b, &out);
        // a start on the switching surface (just switched) is not an event at s = 0
        if gb > 0.0 {
            self.z = out;
            self.tau = tau_b;
            self.last
                .record(&self.model, region, tau0, &z0, self.tau, &self.z);
            check_finite(tau_b, &self.z)?;
            return Ok(Step::plain(tau0, tau_b, region));
        }
        // Illinois (modified regula falsi) on s ↦ g(RK4(z0, s)), s in (0, len]
        let (mut lo, mut glo) = (0.0, g(&self.model, tau0, &z0).max(f64::MIN_POSITIVE));
        let (mut hi, mut ghi) = (len, gb);
        let mut side = 0;
        let mut s = len;
        for _ in 0..200 {
            s = (lo * ghi - hi * glo) / (ghi - glo);
            if !(s > lo && s < hi) {
                s = 0.5 * (lo + hi);
            }
            Self::rk4(&self.model, mode, tau0, &z0, s, &mut self.k, &mut out);
            let gs = g(&self.model, tau0 + s, &out);
            if gs > 0.0 {
                lo = s;
                glo = gs;
                if side == 1 {
                    ghi *= 0.5;
                }
                side = 1;
            } else {
                hi = s;
                ghi = gs;
                if side == -1 {
                    glo *= 0.5;
                }
                side = -1;
            }
            if hi - lo <= 4.0 * f64::EPSILON * (1.0 + tau0.abs()) || gs == 0.0 {
                break;
            }
        }
        Self::rk4(&self.model, mode, tau0, &z0, s, &mut self.k, &mut out);
        let tau_s = tau0 + s;
        self.z = out;
        self.tau = tau_s;
        self.last
            .record(&self.model, region, tau0, &z0, self.tau, &self.z);
        self.region = region.other();
        Ok(Step::switched(&self.model, tau0, region, tau_s, &self.z))
    }

    fn dense_tip(&mut self, tau: f64) -> [f64; 3] {
        self.last.tip(&self.model, tau)
    }

    fn dense_state(&mut self, tau: f64) -> DVector<f64> {
        self.last.state(tau)
    }

    fn last_step_jacobian(&mut self) -> Result<DMatrix<f64>, SimError> {
        Err(SimError::Unsupported {
            integrator: self.name(),
            law: self.model.law_name(),
            hint: "step Jacobians need integrator = \"exact\" or \"adaptive\"",
        })
    }
}

fn check_finite(tau: f64, z: &DVector<f64>) -> Result<(), SimError> {
    let norm = z.norm();
    if norm.is_finite() && norm < 1e12 {
        Ok(())
    } else {
        Err(SimError::Diverged { tau, norm })
    }
}

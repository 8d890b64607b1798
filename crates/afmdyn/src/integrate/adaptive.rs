//! Independent oracle: adaptive DOP853 (Hairer–Nørsett–Wanner) from the `differential-equations`
//! crate, integrating one region at a time with a terminal event on the gap ±V_T (eq. 8).
//!
//! The crate locates the crossing by Brent's method on its dense output, which is only as
//! accurate as the interpolant; the switching time is then polished by Newton's method on
//! g(τ) = ±V_T, every iterate integrated afresh from the step's start to land exactly on it.
//! Steps are cut at a grid of `steps_per_period` points per drive period so that samples and
//! Poincaré sections land on integration points.

use super::exact::checked_start;
use super::{HermiteStep, Integrator, Step};
use crate::error::SimError;
use crate::galerkin::Region;
use crate::model::CantileverModel;
use differential_equations::prelude::*;
use nalgebra::DVector;

struct RegionOde<'a> {
    model: &'a CantileverModel,
    region: Region,
}

impl ODE<f64, Vec<f64>> for RegionOde<'_> {
    fn diff(&self, t: f64, y: &Vec<f64>, dydt: &mut Vec<f64>) {
        let z = DVector::from_column_slice(y);
        let mut dz = DVector::zeros(y.len());
        self.model.rhs(self.region, t, &z, &mut dz);
        dydt.copy_from_slice(dz.as_slice());
    }
}

struct Gap<'a> {
    model: &'a CantileverModel,
    sigma: f64,
}

impl Event<f64, Vec<f64>> for Gap<'_> {
    fn config(&self) -> EventConfig {
        EventConfig::new(CrossingDirection::Negative, Some(1))
    }
    fn event(&self, t: f64, y: &Vec<f64>) -> f64 {
        self.sigma * self.model.v_t(t, &DVector::from_column_slice(y))
    }
}

/// The DOP853 oracle integrator.
#[derive(Debug, Clone)]
pub struct AdaptiveOracle {
    model: CantileverModel,
    tol: f64,
    grid: f64,
    tau: f64,
    z: DVector<f64>,
    region: Region,
    last: HermiteStep,
}

impl AdaptiveOracle {
    /// Relative and absolute tolerance `tol`; steps cut at 64 points per drive period.
    pub fn new(model: &CantileverModel, tol: f64) -> Self {
        let z = DVector::zeros(model.dim());
        AdaptiveOracle {
            model: model.clone(),
            tol,
            grid: model.period() / 64.0,
            tau: 0.0,
            z: z.clone(),
            region: Region::Free,
            last: HermiteStep::new(model.dim()),
        }
    }

    fn integrate_to(
        &self,
        region: Region,
        tau0: f64,
        z0: &DVector<f64>,
        t: f64,
    ) -> Result<DVector<f64>, SimError> {
        if t <= tau0 {
            return Ok(z0.clone());
        }
        let ode = RegionOde {
            model: &self.model,
            region,
        };
        let sol = IVP::ode(&ode, tau0, t, z0.iter().copied().collect::<Vec<f64>>())
            .t_eval([t])
            .method(ExplicitRungeKutta::dop853().rtol(self.tol).atol(self.tol))
            .solve()
            .map_err(|e| SimError::Adaptive {
                tau: tau0,
                message: format!("{e:?}"),
            })?;
        sol.y
            .last()
            .map(|y| DVector::from_column_slice(y))
            .ok_or_else(|| SimError::Adaptive {
                tau: tau0,
                message: "no output point".into(),
            })
    }
}

impl Integrator for AdaptiveOracle {
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
        "adaptive"
    }

    fn reset(&mut self, tau: f64, z: &DVector<f64>) -> Result<(), SimError> {
        self.region = checked_start(&self.model, tau, z)?;
        self.tau = tau;
        self.z.copy_from(z);
        Ok(())
    }

    fn step(&mut self, tau_max: f64) -> Result<Step, SimError> {
        let tau0 = self.tau;
        let k = (tau0 / self.grid).floor() + 1.0;
        let mut next = k * self.grid;
        if next <= tau0 {
            next += self.grid;
        }
        let tf = next.min(tau_max);
        let region = self.region;
        if tf <= tau0 {
            return Ok(Step {
                tau0,
                tau1: tau0,
                region,
                event: None,
            });
        }
        let sigma = if region == Region::Free { 1.0 } else { -1.0 };
        let ode = RegionOde {
            model: &self.model,
            region,
        };
        let gap = Gap {
            model: &self.model,
            sigma,
        };
        let y0: Vec<f64> = self.z.iter().copied().collect();
        let sol = IVP::ode(&ode, tau0, tf, y0)
            .t_eval([tf])
            .event(&gap)
            .method(ExplicitRungeKutta::dop853().rtol(self.tol).atol(self.tol))
            .solve()
            .map_err(|e| SimError::Adaptive {
                tau: tau0,
                message: format!("{e:?}"),
            })?;
        let interrupted = matches!(sol.status, Status::Interrupted);
        let (t_end, y_end) = match (sol.t.last(), sol.y.last()) {
            (Some(t), Some(y)) => (*t, DVector::from_column_slice(y)),
            _ => {
                return Err(SimError::Adaptive {
                    tau: tau0,
                    message: "no output point".into(),
                })
            }
        };
        let z0 = self.z.clone();
        if !interrupted {
            self.z = y_end;
            self.tau = tf;
            self.last
                .record(&self.model, region, tau0, &z0, self.tau, &self.z);
            return Ok(Step {
                tau0,
                tau1: tf,
                region,
                event: None,
            });
        }
        // Newton on the event time, each iterate integrated afresh from the step's start (the
        // crate's event point comes from its dense output, accurate only to the interpolant)
        let mut tau_s = t_end;
        let mut zs = y_end;
        for _ in 0..8 {
            let g = self.model.v_t(tau_s, &zs);
            let dg = self.model.v_t_dot(tau_s, &zs);
            if dg == 0.0 {
                break;
            }
            let delta = -g / dg;
            if delta.abs() <= 4.0 * f64::EPSILON * (1.0 + tau_s.abs()) {
                break;
            }
            tau_s += delta;
            zs = self.integrate_to(region, tau0, &z0, tau_s)?;
        }
        self.z = zs;
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
}

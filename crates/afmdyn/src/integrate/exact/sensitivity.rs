//! Derivatives of the flow over a step: the transition matrices e^{A_s t} (the step Jacobian
//! inside a region) and the parameter sensitivity ∂z/∂p through the particular solution.

use super::forcing::Forced;
use super::modal::MAXD;
use super::ExactPropagator;
use crate::error::SimError;
use crate::linalg::{matmul_into, matvec};
use crate::params::SweepParam;
use crate::system::Region;
use nalgebra::{DMatrix, DVector};
use std::sync::Arc;

/// ∂z_p/∂p of one region's particular solution for a parameter p of the forcing:
/// ∂z_p/∂p(τ) = p0 + ps sin Ωτ + pc cos Ωτ + (∂Ω/∂p) τ (ps⁰ cos Ωτ − pc⁰ sin Ωτ), with
/// (ps⁰, pc⁰) those of [`Forced`]; eq. 10's particular solution differentiated at fixed A:
/// A p0 = −∂b_const/∂p and [[A, ΩI], [−ΩI, A]] (ps, pc) = −(∂b_sin/∂p, ∂b_cos/∂p) −
/// (∂Ω/∂p) (pc⁰, −ps⁰).
#[derive(Debug, Clone)]
pub(super) struct ParticularDerivative {
    p0: DVector<f64>,
    ps: DVector<f64>,
    pc: DVector<f64>,
    d_omega: f64,
}

impl ExactPropagator {
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
    pub(crate) fn step_transition(&self) -> DMatrix<f64> {
        let dim = self.z.len();
        let mut out = DMatrix::zeros(dim, dim);
        self.step_transition_into(&mut out);
        out
    }

    /// [`ExactPropagator::step_transition`] into `out` (resized to 2N×2N if needed): the
    /// cached Φ_s after a whole grid step, without allocating.
    pub(super) fn step_transition_into(&self, out: &mut DMatrix<f64>) {
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
    pub(super) fn particular_derivative_for(
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
    pub(super) fn zpp_into(
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

    /// [`Integrator::last_step_param_derivative_into`](crate::integrate::Integrator::last_step_param_derivative_into):
    /// z(τ1) = z_p(τ1) + e^{A t}(z(τ0) − z_p(τ0)) with A independent of p, so at fixed z(τ0)
    /// ∂z(τ1)/∂p = ∂z_p/∂p(τ1) − e^{A t} ∂z_p/∂p(τ0).
    pub(super) fn last_step_param_derivative_impl(
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
}

//! The state between steps: the particular solution z_p and sin/cos Ωτ at the current time,
//! the plain state formed from the modal coordinates, a stint's entry, and the divergence check.

use super::forcing::Forced;
use super::modal::ModalExp;
use super::ExactPropagator;
use crate::error::SimError;
use crate::linalg::matvec;
use crate::system::Region;

impl ExactPropagator {
    fn zp_into(f: &Forced, omega: f64, tau: f64, out: &mut [f64]) {
        Self::zp_at(f, (omega * tau).sin_cos(), out);
    }

    /// z_p(τ) into `out`, given (sin Ωτ, cos Ωτ).
    pub(super) fn zp_at(f: &Forced, (s, c): (f64, f64), out: &mut [f64]) {
        let (p0, ps, pc) = (f.p0.as_slice(), f.ps.as_slice(), f.pc.as_slice());
        for (((o, a), b), d) in out.iter_mut().zip(p0).zip(ps).zip(pc) {
            *o = a + s * b + c * d;
        }
    }

    /// z = z_p(τ) + T⁻¹ V q in a modal region, when z lags behind q (after modal steps inside
    /// [`Spans::advance_to`]). On a grid point z_p is the grid table's value (column k,
    /// or m at a period end), elsewhere z_p(τ) from sin/cos Ωτ, as a materialising step of
    /// `step_impl` forms it: [`Spans::advance_to`] and the step loop agree bit for bit.
    ///
    /// [`Spans::advance_to`]: crate::integrate::Spans::advance_to
    pub(super) fn materialize(&mut self) {
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
    pub(super) fn zp_now(&self, out: &mut [f64]) {
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
    pub(super) fn trig_now(&self) -> (f64, f64) {
        match self.on_grid {
            Some((_, k)) => self.trig[self.grid.table_column(k)],
            None => self.trig_at(self.tau),
        }
    }

    /// At the end of a period: form the plain state and stop with [`SimError::Diverged`] when
    /// its norm is NaN or reaches 1e12 ([`crate::params::STATE_NORM_MAX`]).
    pub(super) fn check_divergence(&mut self) -> Result<(), SimError> {
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

    /// (sin Ωτ, cos Ωτ): kept from the last switching or reset when τ is its time (the start
    /// of the step after it), formed otherwise.
    pub(super) fn trig_at(&self, tau: f64) -> (f64, f64) {
        match self.entry_trig {
            (t, sc) if t == tau => sc,
            _ => (self.model.omega() * tau).sin_cos(),
        }
    }

    /// Start a stint in `region` at (τ, z): the bound on |W_hom''| over the whole stint and, with
    /// the eigendecomposition, the modal coordinates q = V⁻¹ T δz of the homogeneous part. With
    /// y(t) = Σ v_k e^{λ_k t} q_k the bound is the modal Σ |c̃ᵀv_k| |λ_k|² |q_k| (Re λ_k ≤ 0);
    /// without it, the energy bound ‖c̃ᵀÃ²‖ ‖y‖ (‖e^{Ãt}‖₂ ≤ 1), which is never the smaller one
    /// where both exist (none of 820 stint entries at N = 3 and 358 at N = 10 on the default
    /// attractor). `sc` = (sin Ωτ, cos Ωτ) at the entry time τ.
    pub(super) fn enter_stint(&mut self, region: Region, sc: (f64, f64)) {
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
        self.stints = self.stints.wrapping_add(1);
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
}

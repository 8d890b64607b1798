//! The integrals of the energy-balance rates over a whole grid step in closed form: with
//! z(τ_k + s) = z_p(τ_k + s) + e^{A s} δz₀ over the step (eq. 10) and a rate
//! zᵀQz + l(τ)ᵀz + k(τ) ([`RateForm`], the linear law's rates as quadratic forms),
//!
//! ∫₀ʰ rate ds = δz₀ᵀ G δz₀ + w_kᵀ δz₀ + c_k,
//!
//! G = ∫₀ʰ e^{Aᵀs} Q e^{As} ds (the Gramian-type integral of Van Loan, *IEEE Trans. Autom.
//! Control* 23 (1978) 395, here by quadrature), w_k = ∫₀ʰ e^{Aᵀs}(2Q z_p + l)(τ_k + s) ds and
//! c_k = ∫₀ʰ (z_pᵀQz_p + lᵀz_p + k)(τ_k + s) ds: G per region, w_k and c_k per grid point of a
//! period, tabulated once (lazily, on the first request) by 16-point Gauss–Legendre on the
//! exact e^{As} — exact to round-off, since on a grid step ‖Ã‖h ≤ θ = 4 and the integrands are
//! entire with frequencies ≤ 2θ/h (the 16-point rule's error for e^{8is} on [0, 1] is below
//! 1e-16). A recorded grid step then costs three quadratic forms of size 2N instead of 12
//! states of dense output with their rates (`trajectory::record`).

use super::modal::ModalExp;
use super::ExactPropagator;
use crate::model::RateForm;
use crate::system::Region;
use gauss_quad::legendre::GaussLegendre;
use nalgebra::{DMatrix, DVector};
use std::num::NonZeroUsize;

/// Gauss–Legendre points per grid step of the tables.
const NODES: usize = 16;

/// The tables of one region (module docs).
#[derive(Debug)]
pub(super) struct EnergyTable {
    /// G of each rate (2N×2N); `None` where Q = 0.
    g: [Option<DMatrix<f64>>; 3],
    /// w_k of the three rates, grid point k major: `[m][3][2N]`.
    w: Vec<f64>,
    /// c_k of the three rates, `[m][3]`.
    c: Vec<[f64; 3]>,
}

impl ExactPropagator {
    /// The tables of region `r` (module docs).
    fn energy_table(&self, r: Region) -> Option<EnergyTable> {
        let forms: [RateForm; 3] = self.model.rate_forms(r)?;
        let dim = self.z.len();
        let (m, h) = (self.grid.m, self.grid.h);
        let omega = self.model.omega();
        let a = &self.model.dynamics(r).a;
        let fr = &self.forced[r.index()];
        let gl = GaussLegendre::new(NonZeroUsize::new(NODES).expect("nonzero"));
        // nodes s_i on [0, h], weights, e^{A s_i}
        let nodes: Vec<(f64, f64, DMatrix<f64>)> = gl
            .iter()
            .map(|(x, wt)| {
                let s = 0.5 * h * (x + 1.0);
                (s, 0.5 * h * wt, (a * s).exp())
            })
            .collect();
        let g = std::array::from_fn(|t| {
            let q = &forms[t].q;
            (q.amax() > 0.0).then(|| {
                let mut g = DMatrix::zeros(dim, dim);
                for (_, wt, phi) in &nodes {
                    g += (phi.transpose() * q * phi) * *wt;
                }
                0.5 * (&g + g.transpose())
            })
        });
        let mut w = vec![0.0; m * 3 * dim];
        let mut c = vec![[0.0; 3]; m];
        let (mut zp, mut l, mut v) = (
            DVector::zeros(dim),
            DVector::zeros(dim),
            DVector::zeros(dim),
        );
        for k in 0..m {
            for (s, wt, phi) in &nodes {
                let sc = (omega * (k as f64 * h + s)).sin_cos();
                Self::zp_at(fr, sc, zp.as_mut_slice());
                for (t, form) in forms.iter().enumerate() {
                    form.linear_at(sc, l.as_mut_slice());
                    // v = 2 Q z_p + l; w_k += wt e^{Aᵀs} v; c_k += wt (z_pᵀQz_p + lᵀz_p + k)
                    v.gemv(2.0, &form.q, &zp, 0.0);
                    let quad = 0.5 * v.dot(&zp);
                    v += &l;
                    let out = &mut w[(k * 3 + t) * dim..(k * 3 + t + 1) * dim];
                    for (j, o) in out.iter_mut().enumerate() {
                        *o += wt * phi.column(j).dot(&v);
                    }
                    c[k][t] += wt * (quad + l.dot(&zp) + form.constant_at(sc));
                }
            }
        }
        Some(EnergyTable { g, w, c })
    }

    /// [∫ base power, ∫ beam dissipation, ∫ sample dissipation] over the last step when it was
    /// a whole grid step (module docs); `None` otherwise (the caller integrates the dense
    /// output), and for a model without rate forms.
    pub(super) fn last_step_rate_integrals_impl(&mut self) -> Option<[f64; 3]> {
        // a whole grid step that ran its full length (a switching inside ends it early)
        let len = self.tau - self.last.tau0;
        let h = self.grid.h;
        if !self.last.full || (len - h).abs() > 8.0 * f64::EPSILON * (h + self.tau.abs()) {
            return None;
        }
        if self.energy.is_none() {
            let tables = [
                self.energy_table(Region::Free)?,
                self.energy_table(Region::Contact)?,
            ];
            self.energy = Some(std::sync::Arc::new(tables));
        }
        let ri = self.last.region.index();
        let tab = &self.energy.as_ref()?[ri];
        let dim = self.z.len();
        // δz₀ of the step in plain coordinates
        let mut d0 = [0.0; super::modal::MAXD];
        let d0 = &mut d0[..dim];
        match (&self.spec[ri].modal, self.last.modal) {
            (Some(me), true) => ModalExp::expand(&me.tv, &self.last.q0, d0, false),
            _ => d0.copy_from_slice(self.last.dz0.as_slice()),
        }
        let k = self.last.k;
        let mut out = [0.0; 3];
        for (t, o) in out.iter_mut().enumerate() {
            let w = &tab.w[(k * 3 + t) * dim..(k * 3 + t + 1) * dim];
            let mut e = tab.c[k][t] + w.iter().zip(d0.iter()).map(|(a, b)| a * b).sum::<f64>();
            if let Some(g) = &tab.g[t] {
                for (j, col) in g.column_iter().enumerate() {
                    e += d0[j] * col.iter().zip(d0.iter()).map(|(a, b)| a * b).sum::<f64>();
                }
            }
            *o = e;
        }
        Some(out)
    }
}

//! The contact flow's recurrences: in the regularising time σ ([`Jet::contact`]) and, away
//! from the contact's edges, in τ ([`Jet::contact_interior`]) (the parent module's docs).

// the recurrences index several series by the order k and by k − j at once
#![allow(clippy::needless_range_loop)]

use super::*;

impl Jet {
    /// The tip force's coefficient of order k in contact from the series of δ, δ̇ and w (w up
    /// to order k in `wrev`), in τ or in σ alike: F_c = α4 wδ + α6 δ̇ (Hertz),
    /// −H̃/ã₀² + α4 wδ + α6 wδ̇ (DMT; module docs).
    #[inline(always)]
    fn contact_force(&self, s: &Series, k: usize) -> f64 {
        let wdel = cauchy_rev(&s.del, &s.wrev, k);
        match self.law {
            Law::Hertz { k: k4, c } => k4 * wdel + c * s.deld[k],
            Law::Dmt { h, a0, k: k4, c } => {
                let adhesion = if k == 0 { -h / (a0 * a0) } else { 0.0 };
                let kv = if c == 0.0 {
                    0.0
                } else {
                    c * cauchy_rev(&s.deld, &s.wrev, k)
                };
                adhesion + k4 * wdel + kv
            }
        }
    }

    /// The series of the contact flow from (τ₀, z₀) in τ − τ₀ to `order` (with Φ(τ₀) = I when
    /// variational), into `s`: a step inside the contact, δ₀ = `w0`² > 0. The field is
    /// the free flight's linear one plus M⁻¹φ F_c with F_c from w = √δ, whose series follows
    /// from w² = δ (the square root's recurrence, module docs), analytic while δ stays off 0 — the radius the step rule reads is
    /// the distance to the complex time where δ = 0. Per order: two or three products of series
    /// (w², w δ, for DMT's damper w δ̇ and δ̇/w), where the σ-series of [`Jet::contact`] takes one
    /// per state component.
    pub(crate) fn contact_interior(
        &self,
        s: &mut Series,
        t0: f64,
        z0: &[f64],
        w0: f64,
        order: Order,
    ) {
        with_width!(self.n, w => self.contact_interior_w(w, s, t0, z0, w0, order))
    }

    fn contact_interior_w<W: Width>(
        &self,
        wd: W,
        s: &mut Series,
        t0: f64,
        z0: &[f64],
        w0: f64,
        order: Order,
    ) {
        let Order { p, variational } = order;
        let n = wd.get();
        let d = 2 * n;
        let (sn, cs) = s.start(order, d, Region::Contact, t0, z0, self.omega);
        s.sigma = false;
        self.trig_series(s, sn, cs, p);
        s.theta[..=p].fill(0.0);
        let om = self.omega;
        let mut cur = [0.0; 2 * crate::params::MAX_MODES];
        let cur = &mut cur[..d];
        cur.copy_from_slice(z0);
        let inv_2w0 = 0.5 / w0;
        for k in 0..=p {
            let zk = &*cur;
            let v = self.v_t_coefficient(&zk[..n], k, s.s[k]);
            let vd = dot(&self.phi[..n], &zk[n..]) + self.base * om * s.c[k];
            s.v[k] = v;
            s.del[k] = -v;
            s.deld[k] = -vd;
            // w = √δ: 2 w₀ w_k = δ_k − Σ_{0<j<k} w_j w_{k−j}
            let wk = if k == 0 {
                w0
            } else {
                let old = dot(&s.w[1..k], &s.wrev[M - k..M - 1]);
                (s.del[k] - old) * inv_2w0
            };
            s.w[k] = wk;
            s.wrev[M - 1 - k] = wk;
            if k == p {
                break;
            }
            if variational {
                match self.law {
                    Law::Hertz { k: k4, c } => {
                        // ∂F_c/∂V_T = −(3/2) α4 w, ∂F_c/∂(dV_T/dτ) = −α6
                        s.fv[k] = -1.5 * k4 * wk;
                        s.fvd[k] = if k == 0 { -c } else { 0.0 };
                    }
                    Law::Dmt { k: k4, c, .. } => {
                        // ∂F_c/∂δ = (3/2) α4 w + α6 δ̇/(2w), ∂F_c/∂δ̇ = α6 w; q = δ̇/w from
                        // w q = δ̇ (in `u`)
                        let q = if c == 0.0 {
                            0.0
                        } else {
                            let old = dot(&s.u[..k], &s.wrev[M - 1 - k..M - 1]);
                            (s.deld[k] - old) / w0
                        };
                        s.u[k] = q;
                        s.fv[k] = -1.5 * k4 * wk - 0.5 * c * q;
                        s.fvd[k] = -c * wk;
                    }
                }
            }
            let f = self.contact_force(s, k);
            s.f[k] = f;
            self.next_order(wd, s, cur, k, f);
            if variational {
                self.next_phi_order(wd, s, k, true);
            }
        }
    }

    /// The series of the contact flow from (τ₀, z₀), w(0) = `w0` (= √δ₀), in σ to `order`
    /// (with Φ(τ₀) = I when variational), into `s`.
    pub(crate) fn contact(&self, s: &mut Series, t0: f64, z0: &[f64], w0: f64, order: Order) {
        with_width!(self.n, w => self.contact_w(w, s, t0, z0, w0, order))
    }

    fn contact_w<W: Width>(
        &self,
        wd: W,
        s: &mut Series,
        t0: f64,
        z0: &[f64],
        w0: f64,
        order: Order,
    ) {
        let Order { p, variational } = order;
        let n = wd.get();
        let d = 2 * n;
        let dd = d * d;
        let (sn, cs) = s.start(order, d, Region::Contact, t0, z0, self.omega);
        s.s[0] = sn;
        s.c[0] = cs;
        self.component_sigma_start(s);
        s.theta[0] = 0.0;
        s.w[0] = w0;
        s.wrev[M - 1] = w0;
        let om = self.omega;
        for k in 0..=p {
            let (v, vd) = {
                let zk = &s.z[k * d..(k + 1) * d];
                (
                    self.v_t_coefficient(&zk[..n], k, s.s[k]),
                    dot(&self.phi[..n], &zk[n..]) + self.base * om * s.c[k],
                )
            };
            s.v[k] = v;
            s.del[k] = -v;
            s.deld[k] = -vd;
            if k == p {
                break;
            }
            let inv = 1.0 / (k + 1) as f64;
            s.w[k + 1] = s.deld[k] * inv;
            s.wrev[M - 2 - k] = s.w[k + 1];
            s.theta[k + 1] = 2.0 * s.w[k] * inv;
            // the tip force and 2w ∂F_c/∂V_T, 2w ∂F_c/∂(dV_T/dτ)
            if variational {
                // 2w ∂F_c/∂V_T and 2w ∂F_c/∂(dV_T/dτ) (module docs)
                match self.law {
                    Law::Hertz { k: k4, c } => {
                        s.fv[k] = -3.0 * k4 * s.del[k];
                        s.fvd[k] = -2.0 * c * s.w[k];
                    }
                    Law::Dmt { k: k4, c, .. } => {
                        s.fv[k] = -3.0 * k4 * s.del[k] - c * s.deld[k];
                        s.fvd[k] = -2.0 * c * s.del[k];
                    }
                }
            }
            let f = self.contact_force(s, k);
            s.f[k] = f;
            // g_k = f(τ, z)_k (component-major), then z_{k+1} = 2 (w ⋆ g)_k / (k + 1): the terms
            // of the earlier orders of g first, the newest, w₀ g_k, last
            {
                let mut lower = [0.0; crate::params::MAX_MODES];
                let zs = &s.z[k * d..(k + 1) * d];
                self.lower_field(wd, zs, s, k, f, &mut lower[..n]);
                for i in 0..n {
                    s.g[i * M + k] = zs[n + i];
                    s.g[(n + i) * M + k] = lower[i];
                }
            }
            {
                // Σ_{j=1..=k} w_j g_{k−j}: g_m pairs with w_{k−m} = wrev[M − 1 − k + m]
                let wk = &s.wrev[M - 1 - k..M - 1];
                let (w0, two) = (s.w[0], 2.0 * inv);
                for i in 0..d {
                    let gi = &s.g[i * M..i * M + k + 1];
                    let old = dot(&gi[..k], wk);
                    s.z[(k + 1) * d + i] = two * (old + w0 * gi[k]);
                }
            }
            // sin and cos of Ωτ(σ): S′ = Ω C τ′, C′ = −Ω S τ′, τ′ = 2w
            s.s[k + 1] = 2.0 * om * cauchy_rev(&s.c, &s.wrev, k) * inv;
            s.c[k + 1] = -2.0 * om * cauchy_rev(&s.s, &s.wrev, k) * inv;
            if !self.components.is_empty() {
                self.component_sigma_next(s, k);
            }
            if variational {
                {
                    let phik = &s.phi[k * dd..(k + 1) * dd];
                    let (gk, r, rd) = (
                        &mut s.gphi[k * dd..(k + 1) * dd],
                        &mut s.r[k * d..(k + 1) * d],
                        &mut s.rd[k * d..(k + 1) * d],
                    );
                    self.a_times_phi(wd, phik, gk, r, rd);
                }
                let next = &mut s.phi[(k + 1) * dd..(k + 1) * dd + dd];
                next.fill(0.0);
                for j in 0..=k {
                    let wj = 2.0 * s.w[j] * inv;
                    let gk = &s.gphi[(k - j) * dd..(k - j) * dd + dd];
                    for i in 0..dd {
                        next[i] += wj * gk[i];
                    }
                }
                for col in 0..d {
                    let mut rank = 0.0;
                    for j in 0..=k {
                        rank +=
                            s.fv[j] * s.r[(k - j) * d + col] + s.fvd[j] * s.rd[(k - j) * d + col];
                    }
                    let rank = rank * inv;
                    let o = &mut next[col * d + n..(col + 1) * d];
                    for (oi, m) in o.iter_mut().zip(&self.mphi) {
                        *oi += m * rank;
                    }
                }
            }
        }
    }
}

//! The series' accessors and their evaluation (Horner's scheme) at a point of the step.

use super::*;

impl Series {
    /// Start the series of a step from (τ₀, z₀) to `order`: buffers sized, z's order 0,
    /// Φ(τ₀) = I when variational; returns (sin Ωτ₀, cos Ωτ₀).
    pub(super) fn start(
        &mut self,
        order: Order,
        d: usize,
        region: Region,
        t0: f64,
        z0: &[f64],
        omega: f64,
    ) -> (f64, f64) {
        let Order { p, variational } = order;
        self.prepare(p, d, variational, region, t0);
        self.z[..d].copy_from_slice(z0);
        if variational {
            let phi0 = &mut self.phi[..d * d];
            phi0.fill(0.0);
            for i in 0..d {
                phi0[i * d + i] = 1.0;
            }
        }
        (omega * t0).sin_cos()
    }

    /// Size the buffers for dimension `d` (allocated on the first step and when d changes).
    pub(super) fn prepare(
        &mut self,
        p: usize,
        d: usize,
        variational: bool,
        region: Region,
        t0: f64,
    ) {
        assert!(p < M, "Taylor order {p} beyond {MAX_ORDER}");
        self.p = p;
        self.variational = variational;
        self.region = region;
        self.sigma = region == Region::Contact;
        self.t0 = t0;
        if self.d != d || self.z.len() != M * d {
            self.d = d;
            for v in [&mut self.z, &mut self.g, &mut self.r, &mut self.rd] {
                v.clear();
                v.resize(M * d, 0.0);
            }
            self.phi.clear();
            self.gphi.clear();
        }
        if variational && self.phi.len() != M * d * d {
            self.phi.resize(M * d * d, 0.0);
            self.gphi.resize(M * d * d, 0.0);
        }
    }

    /// The state at s (τ − τ₀ in free flight, σ in contact) into `out` (d), by Horner's scheme.
    pub(crate) fn state_at(&self, s: f64, out: &mut [f64]) {
        with_width!(self.d / 2, w => horner_fixed(w, &self.z, self.p, s, out))
    }

    /// Φ at s into `out` (d², column-major).
    pub(crate) fn jacobian_at(&self, s: f64, out: &mut [f64]) {
        let dd = self.d * self.d;
        horner_vec(&self.phi, dd, self.p, s, out);
    }

    /// ∞-norms of the coefficients of order k of everything the step carries (state, Φ, the
    /// drive's sin Ωτ and cos Ωτ — the energy balance integrates products with them —, and in
    /// contact τ − τ₀ and w): the input of the step-size rule.
    pub(crate) fn order_norm(&self, k: usize) -> f64 {
        let d = self.d;
        let mut m = self.z[k * d..(k + 1) * d]
            .iter()
            .fold(self.s[k].abs().max(self.c[k].abs()), |a, x| a.max(x.abs()));
        if self.region == Region::Contact {
            m = m.max(self.w[k].abs());
            if self.sigma {
                m = m.max(self.theta[k].abs());
            }
        }
        if self.variational {
            let dd = d * d;
            m = self.phi[k * dd..(k + 1) * dd]
                .iter()
                .fold(m, |a, x| a.max(x.abs()));
        }
        m
    }

    /// The indentation δ = −V_T (contact).
    pub(crate) fn depth(&self) -> &[f64] {
        &self.del[..=self.p]
    }

    /// The guard's series: V_T in free flight, w in contact (both positive inside the region).
    pub(crate) fn guard(&self) -> &[f64] {
        match self.region {
            Region::Free => &self.v[..=self.p],
            Region::Contact => &self.w[..=self.p],
        }
    }
}

/// [`horner_vec`] for the state (width 2N, a constant of the monomorphised loop for small N).
#[inline(always)]
pub(super) fn horner_fixed<W: Width>(w: W, c: &[f64], p: usize, s: f64, out: &mut [f64]) {
    // the even and the odd orders in two chains of Horner's scheme in s² (half the latency):
    // Σ c_k sᵏ = E(s²) + s O(s²)
    let d = 2 * w.get();
    let mut even = [0.0; 2 * crate::params::MAX_MODES];
    let mut odd = [0.0; 2 * crate::params::MAX_MODES];
    let (even, odd) = (&mut even[..d], &mut odd[..d]);
    let s2 = s * s;
    let top = p - p % 2;
    for k in (0..=top).rev().step_by(2) {
        let ce = &c[k * d..k * d + d];
        for i in 0..d {
            even[i] = even[i] * s2 + ce[i];
        }
        if k < p {
            let co = &c[(k + 1) * d..(k + 1) * d + d];
            for i in 0..d {
                odd[i] = odd[i] * s2 + co[i];
            }
        }
    }
    for i in 0..d {
        out[i] = even[i] + s * odd[i];
    }
}

/// Σ_k c_k sᵏ for each of the `width` components of the order-major coefficients `c`
/// (orders 0..=p), into `out`.
pub(crate) fn horner_vec(c: &[f64], width: usize, p: usize, s: f64, out: &mut [f64]) {
    let mut orders = c[..(p + 1) * width].chunks_exact(width).rev();
    if let Some(top) = orders.next() {
        out.copy_from_slice(top);
    }
    for ck in orders {
        for (o, &x) in out.iter_mut().zip(ck) {
            *o = *o * s + x;
        }
    }
}

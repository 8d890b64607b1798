//! [`HybridSystem`] for [`CantileverModel`]: the regions, guards, jumps and the flow the
//! integrators and analyses read.

use super::*;

impl HybridSystem for CantileverModel {
    fn dim(&self) -> usize {
        CantileverModel::dim(self)
    }
    fn period(&self) -> f64 {
        self.period
    }

    /// Contact when V_T < 0, or V_T = 0 moving inwards (dV_T/dτ ≤ 0); free otherwise. For the
    /// impact law: sticking when V_T = 0, dV_T/dτ = 0 and the constraint force λ > 0. For a
    /// hysteretic law (JKR) also contact for 0 ≤ V_T < |δ_f| moving away (dV_T/dτ > 0: the
    /// neck), the region being history-dependent there.
    fn mode_at(&self, tau: f64, z: &[f64]) -> Region {
        let (mut v, mut vd) = self.v_t_pair(tau, z);
        if let Some((zn, u)) = self.zener_state(z) {
            // over the SLS surface: g = V_T + s(u), ġ = V̇_T + s′u̇ (u̇ is continuous at g = 0)
            v += zn.surface(u);
            vd += zn.surface_gain() * zn.rate(false, -v, u);
        }
        if self.law.law().restitution().is_some() {
            if v <= 0.0 && vd == 0.0 && self.sticking_force_value(tau, z) > 0.0 {
                Region::Contact
            } else {
                Region::Free
            }
        } else if v < 0.0 || (v == 0.0 && vd <= 0.0) || (v < self.release && vd > 0.0) {
            // a hysteretic law's band 0 ≤ V_T < |δ_f|: in contact when leaving through the
            // neck, free when approaching ([`ContactLaw::release_distance`])
            Region::Contact
        } else {
            Region::Free
        }
    }

    fn rhs(&self, mode: Region, tau: f64, z: &[f64], dz: &mut [f64]) {
        self.rhs_slice(mode, tau, z, dz);
    }

    fn jacobian(&self, mode: Region, tau: f64, z: &[f64], jac: &mut DMatrix<f64>) {
        self.jacobian_into(mode, tau, z, jac);
    }

    /// Free flight: g = V_T; contact: g = −V_T, or |δ_f| − V_T for a hysteretic law (JKR's
    /// neck); sticking (impact law): g = λ; over the SLS sample σ(V_T + s(u)) (the contact's
    /// being F_c/(α4 + κ): the tip leaves where the sample's force falls to 0).
    fn guard(&self, mode: Region, tau: f64, z: &[f64]) -> Guard {
        if mode == Region::Contact && self.law.law().restitution().is_some() {
            return self.sticking_force(tau, z);
        }
        let n = self.modes();
        let p = &self.params;
        let sigma = mode.guard_sign();
        let mut grad = DVector::zeros(self.dim());
        grad.rows_mut(0, n).copy_from(&(sigma * self.tip()));
        if let Some((zn, _)) = self.zener_state(z) {
            grad[2 * n] = sigma * zn.surface_gain();
        }
        Guard {
            value: sigma * self.switching(self.v_t_pair(tau, z).0, z) + self.guard_offset(mode),
            grad,
            d_tau: sigma * p.base_amplitude() * p.omega * (p.omega * tau).cos(),
        }
    }

    fn guard_value(&self, mode: Region, tau: f64, z: &[f64]) -> f64 {
        if mode == Region::Contact && self.law.law().restitution().is_some() {
            return self.sticking_force_value(tau, z);
        }
        mode.guard_sign() * self.switching(self.v_t_pair(tau, z).0, z) + self.guard_offset(mode)
    }

    /// Switchings are the identity; the impact law's free-flight guard is an impact (module
    /// docs), ending in sticking (a plastic impact) when the bounce would rise less than
    /// `STICK_HEIGHT_TOLERANCES` guard tolerances against λ > 0; sticking ends in a release
    /// (identity).
    fn jump(&self, from: Region, tau: f64, z: &[f64]) -> Jump {
        let Some(r) = self.law.law().restitution() else {
            return Jump::switching(from.other(), z);
        };
        if from == Region::Contact {
            let mut j = Jump::switching(Region::Free, z);
            j.kind = EventKind::Release;
            return j;
        }
        let n = self.modes();
        let p = &self.params;
        let (_, v_minus) = self.v_t_pair(tau, z);
        // ȧ⁺ = ȧ⁻ − (1 + r) m_eff V̇_T⁻ M⁻¹φ; the plastic impact (r = 0) first when sticking
        let apply = |r: f64| {
            let mut state = DVector::from_column_slice(z);
            let k = (1.0 + r) * self.m_eff * v_minus;
            for (o, m) in state.rows_mut(n, n).iter_mut().zip(self.mphi.iter()) {
                *o -= k * m;
            }
            state
        };
        let plastic = apply(0.0);
        // stick when λ is compressive (or within its dead band of 0: about to become so) and the
        // bounce would rise less than the resolvable height
        let lambda = self.sticking_force_value(tau, plastic.as_slice());
        let bounce = r * v_minus;
        let h_stick =
            STICK_HEIGHT_TOLERANCES * self.guard_tolerance(Region::Free, tau, plastic.as_slice());
        let sticks = lambda > -self.guard_tolerance(Region::Contact, tau, plastic.as_slice())
            && self.m_eff * bounce * bounce <= 2.0 * h_stick * lambda.max(0.0);
        let r_eff = if sticks { 0.0 } else { r };
        let state = if sticks { plastic } else { apply(r) };
        // R = I − (1 + r) m_eff [0 0; M⁻¹φ φᵀ 0] on the velocity block (V̇_T⁻ = φᵀȧ + α2Ω cos Ωτ)
        let mut jacobian = DMatrix::identity(2 * n, 2 * n);
        let k = (1.0 + r_eff) * self.m_eff;
        let mut block = jacobian.view_mut((n, n), (n, n));
        block.ger(-k, &self.mphi, self.tip(), 1.0);
        // ∂ȧ⁺/∂τ = −(1 + r) m_eff M⁻¹φ ∂V̇_T⁻/∂τ, ∂V̇_T⁻/∂τ = −α2 Ω² sin Ωτ
        let mut d_tau = DVector::zeros(2 * n);
        let dv = -p.base_amplitude() * p.omega * p.omega * (p.omega * tau).sin();
        d_tau.rows_mut(n, n).copy_from(&(-k * dv * &self.mphi));
        Jump {
            to: if sticks {
                Region::Contact
            } else {
                Region::Free
            },
            kind: if sticks {
                EventKind::Stick
            } else {
                EventKind::Impact
            },
            state,
            jacobian,
            d_tau,
        }
    }

    fn is_affine(&self) -> bool {
        self.law.law().is_affine()
    }

    /// σ dV_T/dτ = σ(φ·ȧ + α2 Ω cos Ωτ) for the V_T guards (ȧ = f's top half), without
    /// allocating; the sticking guard through [`HybridSystem::guard`].
    fn guard_rate(&self, mode: Region, tau: f64, z: &[f64], f: &[f64]) -> f64 {
        if mode == Region::Contact && self.law.law().restitution().is_some() {
            let g = self.sticking_force(tau, z);
            return g.grad.iter().zip(f).map(|(a, b)| a * b).sum::<f64>() + g.d_tau;
        }
        let p = &self.params;
        let n = p.modes;
        let wd: f64 = self
            .tip()
            .as_slice()
            .iter()
            .zip(&f[..n])
            .map(|(a, b)| a * b)
            .sum();
        let surface = self
            .zener_state(z)
            .map_or(0.0, |(zn, _)| zn.surface_gain() * f[2 * n]);
        mode.guard_sign() * (wd + p.base_amplitude() * p.omega * (p.omega * tau).cos() + surface)
    }

    /// 1e-12 of the guard's scale: of V_T, 1 + α2 + |α5|; of the constraint force of sticking,
    /// m_eff (1 + α2 Ω²).
    fn guard_tolerance(&self, mode: Region, _tau: f64, _z: &[f64]) -> f64 {
        let p = &self.params;
        if mode == Region::Contact && self.law.law().restitution().is_some() {
            1e-12 * self.m_eff * (1.0 + p.base_amplitude() * p.omega * p.omega)
        } else {
            1e-12 * (1.0 + p.base_amplitude() + p.alpha5.abs())
        }
    }

    /// For DMT in contact the Kelvin–Voigt term makes ∂F_c/∂δ ∋ α6 δ̇/(2√δ), unbounded at contact
    /// onset (integrable: the tangent flow stays finite). With the rank-one nilpotent
    /// E = [0; M⁻¹φ] w [φᵀ 0], w = α6√δ, and Ψ = (I + E)Φ, the singular part cancels against
    /// E′: Ψ′ = (J_reg + [0; M⁻¹φ] w [0 φᵀ]) (I − E) Ψ, all terms bounded (J_reg: the Jacobian
    /// without the singular term; (I + E)⁻¹ = I − E since [φᵀ 0][0; M⁻¹φ] = 0).
    fn variational_rhs(
        &self,
        mode: Region,
        tau: f64,
        z: &[f64],
        psi: &[f64],
        dpsi: &mut [f64],
        jac: &mut DMatrix<f64>,
    ) {
        let d = self.dim();
        let n = self.modes();
        // sin, cos Ωτ once for V_T in the weight and the Jacobian
        let sc = self.base_trig(tau);
        let w = self.kelvin_voigt_weight_at(mode, sc, z);
        self.jacobian_parts(mode, tau, sc, z, jac, w == 0.0);
        if d != 2 * n {
            // internal states: J is not of the second-order form
            crate::system::jacobian_product(jac, psi, dpsi);
            return;
        }
        if w == 0.0 {
            second_order_product(jac, n, psi, dpsi);
            return;
        }
        // J = J_reg + [0; M⁻¹φ] w [0 φᵀ] (velocity rows, velocity columns)
        let tip = self.tip();
        for j in 0..n {
            let wt = w * tip[j];
            for i in 0..n {
                jac[(n + i, n + j)] += self.mphi[i] * wt;
            }
        }
        // J (I − E) Ψ = J Ψ − (J u) vᵀ with E Ψ = u vᵀ, u = [0; M⁻¹φ], v_c = w φᵀ Ψ_top[:, c]
        second_order_product(jac, n, psi, dpsi);
        let mut ju = [0.0; 2 * crate::params::MAX_MODES];
        ju[..n].copy_from_slice(self.mphi.as_slice());
        for i in 0..n {
            ju[n + i] = (0..n).map(|j| jac[(n + i, n + j)] * self.mphi[j]).sum();
        }
        for (out, col) in dpsi.chunks_exact_mut(d).zip(psi.chunks_exact(d)) {
            let v = w * (0..n).map(|j| tip[j] * col[j]).sum::<f64>();
            if v != 0.0 {
                for (o, u) in out.iter_mut().zip(&ju[..d]) {
                    *o -= u * v;
                }
            }
        }
    }

    /// Ψ = (I + E)Φ (forward) or Φ = (I − E)Ψ, E as in [`HybridSystem::variational_rhs`].
    fn to_tangent_coords(&self, mode: Region, tau: f64, z: &[f64], m: &mut [f64], forward: bool) {
        let w = self.kelvin_voigt_weight(mode, tau, z);
        if w == 0.0 {
            return;
        }
        let d = self.dim();
        let n = self.modes();
        let sign = if forward { w } else { -w };
        let tip = self.tip();
        // velocity rows ± M⁻¹φ w (φᵀ M_top), column by column
        for col in m.chunks_exact_mut(d) {
            let top = sign * (0..n).map(|j| tip[j] * col[j]).sum::<f64>();
            if top != 0.0 {
                for (o, u) in col[n..].iter_mut().zip(self.mphi.iter()) {
                    *o += u * top;
                }
            }
        }
    }
}

/// J Ψ for the Jacobian of a second-order system in z = (a, ȧ), J = [[0, I], [L]] (`jac`'s top
/// rows are not read): the top rows are Ψ's lower rows, the lower rows L Ψ
/// ([`crate::system::jacobian_rows_product`]). Ψ and the output are 2n × 2n column-major.
fn second_order_product(jac: &DMatrix<f64>, n: usize, psi: &[f64], dpsi: &mut [f64]) {
    for (out, col) in dpsi.chunks_exact_mut(2 * n).zip(psi.chunks_exact(2 * n)) {
        out[..n].copy_from_slice(&col[n..]);
    }
    crate::system::jacobian_rows_product(jac, n, psi, dpsi);
}

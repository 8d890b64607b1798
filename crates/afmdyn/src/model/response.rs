//! The model's energy balance, responses and parameter derivatives.

use super::*;

impl CantileverModel {
    /// Stored energy E = ½ȦᵀMȦ + ½XᵀK^I X + U(δ), U the potential of the law's conservative
    /// part (½α4 V_T² for the linear law in contact; continuous across a switching; the energy
    /// in the SLS sample's springs, [`Zener::potential`], in and out of contact).
    pub fn energy(&self, r: Region, tau: f64, z: &DVector<f64>) -> f64 {
        let n = self.modes();
        let g = self.galerkin.region(Region::Free);
        let x = z.rows(0, n);
        let v = z.rows(n, n);
        // the products into a buffer on the stack (the same gemv, no allocation)
        let mut buf = [0.0; crate::params::MAX_MODES];
        let mut quad = |m: &DMatrix<f64>, y| {
            let mut out = nalgebra::DVectorViewMut::from_slice(&mut buf[..n], n);
            m.mul_to(&y, &mut out);
            out.dot(&y)
        };
        let kinetic = 0.5 * quad(&g.mass, v);
        let bending = 0.5 * quad(&g.stiffness, x);
        let contact = r == Region::Contact;
        let delta = -self.v_t(tau, z);
        let sample = match self.zener_state(z.as_slice()) {
            Some((zn, u)) => zn.potential(contact, delta, u),
            None => self.law.potential(contact, delta),
        };
        kinetic + bending + sample
    }

    /// The rates of the energy balance at (τ, z) in region r. Multiplying the equation of
    /// motion by Ȧᵀ gives dE/dτ = P_base − D_beam − D_contact exactly, with
    /// P_base = ȦᵀF^I(τ) − α2 Ω cos Ωτ · F_c (plus the power F̃(τ) Ẇ(1,τ) of the further
    /// components of a multifrequency drive, `Params::component_force`) and D_contact = F_d δ̇ (F_d the dissipative part
    /// of the law).
    pub(crate) fn power(&self, r: Region, tau: f64, z: &DVector<f64>) -> PowerTerms {
        let n = self.modes();
        let p = &self.params;
        let g = self.galerkin.region(Region::Free);
        let v = z.rows(n, n);
        let (s, c) = (p.omega * tau).sin_cos();
        let mut drive = g.forcing.sin.dot(&v) * s + g.forcing.cos.dot(&v) * c;
        if p.is_multifrequency() {
            drive += p.component_force(tau) * self.tip().dot(&v);
        }
        // ȦᵀC^IȦ with the damping matrix of eq. 12 (α3 diag(s) with a per-mode damping profile:
        // the beam's per-mode Q, the eigenmode model)
        let beam = (&g.damping * v).dot(&v);
        let fc = self.contact_force(r, tau, z);
        let rate = -self.v_t_dot(tau, z);
        let delta = -self.v_t(tau, z);
        PowerTerms {
            base: drive - p.base_amplitude() * p.omega * c * fc,
            beam_dissipation: beam,
            contact_dissipation: match self.zener_state(z.as_slice()) {
                // the SLS dashpot, also while the surface recovers after the tip left
                Some((zn, u)) => zn.dissipation(r == Region::Contact, delta, u),
                None => self.law.dissipative(r == Region::Contact, delta, rate) * rate,
            },
        }
    }

    /// Energy bookkeeping of an impact at τ with pre-impact rate V̇_T⁻ = `v_minus` and
    /// restitution r: (loss in the sample, work of the impulse on the clamped frame). The
    /// kinetic energy of the motion relative to the sample changes by −(1 − r²) ½ m_eff (V̇_T⁻)²;
    /// the impulse P = −(1 + r) m_eff V̇_T⁻ at the tip also does the work −P α2 Ω cos Ωτ, so
    /// ΔE = −loss + base (derivation in `docs/contact-laws.md`).
    pub(crate) fn impact_energy(&self, tau: f64, v_minus: f64, restitution: f64) -> (f64, f64) {
        let p = &self.params;
        let base_velocity = p.base_amplitude() * p.omega * (p.omega * tau).cos();
        let loss = 0.5 * (1.0 - restitution * restitution) * self.m_eff * v_minus * v_minus;
        let base = (1.0 + restitution) * self.m_eff * v_minus * base_velocity;
        (loss, base)
    }

    /// Complex amplitude H of the free steady response of the tip deflection (no sample force,
    /// the linear free system of eqs. 11–14): W(1,τ) = Im(H e^{i(Ωτ + ψ)}) with ψ the drive
    /// phase (`Params::drive_phase`), so |H| is the free amplitude A₀ (units of g₀) and
    /// −arg H the phase lag behind the drive. From (K − Ω²M + iΩC) X = F_s + i F_c for the
    /// forcing F_s sin Ωτ + F_c cos Ωτ, H = φ(1)ᵀX e^{−iψ} (the harmonic-balance solution of a
    /// linear system, e.g. Meirovitch, *Fundamentals of Vibrations*, McGraw-Hill 2001, §7.15).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] when Ω is at an undamped natural frequency (no steady state).
    pub fn free_tip_response(&self) -> Result<nalgebra::Complex<f64>, SimError> {
        Ok(self.free_tip_response_solved()?.0)
    }

    /// [`CantileverModel::free_tip_response`] H and its derivative dH/dα3 in the lever's
    /// damping α3 (`crate::galerkin::Galerkin::damping_derivative`): differentiating
    /// D X = F with D = K − Ω²M + iΩC, dX/dα3 = D⁻¹(dF/dα3 − iΩ diag(s) X), and
    /// dH = φ(1)ᵀ dX e^{−iψ}. The free amplitude set by an instrument fixes |H| α2; with α3
    /// moving, α2 follows as 1/|H| (d|H|/dα3 = Re(H̄ dH/dα3)/|H|).
    ///
    /// # Errors
    /// As [`CantileverModel::free_tip_response`].
    pub(crate) fn free_tip_response_damping_derivative(
        &self,
    ) -> Result<(nalgebra::Complex<f64>, nalgebra::Complex<f64>), SimError> {
        use nalgebra::Complex;
        let (h, lu, x) = self.free_tip_response_solved()?;
        let om = self.params.omega;
        let (s, df) = self.galerkin.damping_derivative();
        let rhs = DVector::from_fn(self.modes(), |i, _| {
            Complex::new(df[0].sin[i], df[0].cos[i]) - Complex::new(0.0, om * s[i]) * x[i]
        });
        let dx = lu.solve(&rhs).ok_or_else(|| {
            SimError::out_of_range("omega", om, "the free system has no steady state")
        })?;
        let dh: Complex<f64> = self.tip().iter().zip(dx.iter()).map(|(p, d)| d * *p).sum();
        Ok((h, dh * Complex::from_polar(1.0, -self.params.drive_phase())))
    }

    /// H, the LU factors of D = K − Ω²M + iΩC and X (module docs of
    /// [`CantileverModel::free_tip_response`]).
    #[allow(clippy::type_complexity)]
    fn free_tip_response_solved(
        &self,
    ) -> Result<
        (
            nalgebra::Complex<f64>,
            nalgebra::LU<nalgebra::Complex<f64>, nalgebra::Dyn, nalgebra::Dyn>,
            DVector<nalgebra::Complex<f64>>,
        ),
        SimError,
    > {
        use nalgebra::Complex;
        let g = self.galerkin.region(Region::Free);
        let om = self.params.omega;
        let f = DVector::from_fn(self.modes(), |i, _| {
            Complex::new(g.forcing.sin[i], g.forcing.cos[i])
        });
        let lu = self.free_dynamic_stiffness(om).lu();
        let x = lu.solve(&f).ok_or_else(|| {
            SimError::out_of_range(
                "omega",
                om,
                "the free system has no steady state at an undamped natural frequency",
            )
        })?;
        let tip: Complex<f64> = self.tip().iter().zip(x.iter()).map(|(p, xi)| xi * *p).sum();
        Ok((
            tip * Complex::from_polar(1.0, -self.params.drive_phase()),
            lu,
            x,
        ))
    }

    /// D(ω) = K − ω²M + iωC of the free region (N×N): the harmonic balance of the free
    /// linear system at the frequency ω.
    fn free_dynamic_stiffness(&self, omega: f64) -> DMatrix<nalgebra::Complex<f64>> {
        let g = self.galerkin.region(Region::Free);
        DMatrix::from_fn(self.modes(), self.modes(), |i, j| {
            nalgebra::Complex::new(
                g.stiffness[(i, j)] - omega * omega * g.mass[(i, j)],
                omega * g.damping[(i, j)],
            )
        })
    }

    /// Complex amplitude H of the free tip deflection's response to a unit force cos(ωτ) at the
    /// tip: W(1,τ) = Re(H e^{iωτ}), so F̃|H| is a force component's free amplitude and −arg H
    /// its phase lag ([`Params::drive_components`]); H = φ(1)ᵀ(K − ω²M + iωC)⁻¹φ(1), the
    /// harmonic balance of the free system as in [`CantileverModel::free_tip_response`].
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] when ω is at an undamped natural frequency.
    pub fn free_force_response(&self, omega: f64) -> Result<nalgebra::Complex<f64>, SimError> {
        let (_, x) = self.free_force_solved(omega)?;
        Ok(self.at_tip(&x))
    }

    /// [`CantileverModel::free_force_response`] H at ω and its derivative dH/dα3 in the
    /// lever's damping: the force at the tip does not move with α3, so
    /// dX/dα3 = −D⁻¹(iω diag(s) X) and dH = φ(1)ᵀ dX (module docs of
    /// [`CantileverModel::free_tip_response_damping_derivative`]). A further drive component
    /// set to a free amplitude A₀ᵢ has F̃ᵢ = A₀ᵢ/|Hᵢ|, which follows α3 as 1/|Hᵢ|.
    ///
    /// # Errors
    /// As [`CantileverModel::free_force_response`].
    pub(crate) fn free_force_response_damping_derivative(
        &self,
        omega: f64,
    ) -> Result<(nalgebra::Complex<f64>, nalgebra::Complex<f64>), SimError> {
        use nalgebra::Complex;
        let (lu, x) = self.free_force_solved(omega)?;
        let s = self.galerkin.damping_profile();
        let rhs = DVector::from_fn(self.modes(), |i, _| -Complex::new(0.0, omega * s[i]) * x[i]);
        let dx = lu.solve(&rhs).ok_or_else(|| no_free_steady_state(omega))?;
        Ok((self.at_tip(&x), self.at_tip(&dx)))
    }

    /// The LU factors of D(ω) and X = D⁻¹φ(1) of a unit tip force at ω.
    #[allow(clippy::type_complexity)]
    fn free_force_solved(
        &self,
        omega: f64,
    ) -> Result<
        (
            nalgebra::LU<nalgebra::Complex<f64>, nalgebra::Dyn, nalgebra::Dyn>,
            DVector<nalgebra::Complex<f64>>,
        ),
        SimError,
    > {
        let lu = self.free_dynamic_stiffness(omega).lu();
        let f = self.tip().map(|v| nalgebra::Complex::new(v, 0.0));
        let x = lu.solve(&f).ok_or_else(|| no_free_steady_state(omega))?;
        Ok((lu, x))
    }

    /// φ(1)ᵀ v: the tip's value of the modal amplitudes `v`.
    fn at_tip(&self, v: &DVector<nalgebra::Complex<f64>>) -> nalgebra::Complex<f64> {
        self.tip().iter().zip(v.iter()).map(|(p, xi)| xi * *p).sum()
    }

    /// The free region's ∂f/∂α3 in the lever's damping α3 (eq. 12, eq. 14): the state's rate
    /// (ȧ, M⁻¹(F(τ) − C ȧ − K a)) moves by (0, M⁻¹(∂F/∂α3(τ) − diag(s) ȧ)). `None` when M
    /// is not positive definite.
    pub(crate) fn damping_derivative(&self) -> Option<DampingDerivative> {
        let (s, df) = self.galerkin.damping_derivative();
        let n = self.modes();
        let chol = self.galerkin.region(Region::Free).mass.clone().cholesky()?;
        let lift = |f: &DVector<f64>| {
            let mut v = DVector::zeros(self.dim());
            v.rows_mut(n, n).copy_from(&chol.solve(f));
            v
        };
        let forcing = ForcingDerivative {
            b_const: lift(&df[0].constant),
            b_sin: lift(&df[0].sin),
            b_cos: lift(&df[0].cos),
            d_omega: 0.0,
        };
        let velocity = -chol.solve(&DMatrix::from_diagonal(&s));
        Some(DampingDerivative { forcing, velocity })
    }

    /// ∂b/∂p of the free and the contact region (in that order) for a parameter p that enters
    /// the forcing only: b = (0, M⁻¹F) lifted from [`Galerkin::forcing_derivative`] (Ω, α2,
    /// α5); `None` for α1, α3, α4, α6, on which A_s depends.
    pub(crate) fn forcing_derivative(&self, param: SweepParam) -> Option<[ForcingDerivative; 2]> {
        let df = self.galerkin.forcing_derivative(param)?;
        let n = self.modes();
        let chol = self.galerkin.region(Region::Free).mass.clone().cholesky()?;
        let lift = |f: &DVector<f64>| {
            let mut v = DVector::zeros(self.dim());
            v.rows_mut(n, n).copy_from(&chol.solve(f));
            v
        };
        let d_omega = f64::from(u8::from(param == SweepParam::Omega));
        let region = |f: &crate::galerkin::Forcing| ForcingDerivative {
            b_const: lift(&f.constant),
            b_sin: lift(&f.sin),
            b_cos: lift(&f.cos),
            d_omega,
        };
        Some([region(&df[0]), region(&df[1])])
    }

    /// ∂g/∂p of the guard of `mode` at fixed (τ, z) for the guards σ V_T (eq. 8: V_T = W(1,τ) +
    /// α2 sin Ωτ + α5, so ∂V_T/∂Ω = α2 τ cos Ωτ, ∂V_T/∂α2 = sin Ωτ for the beam and 0 for the
    /// point mass, ∂V_T/∂α5 = 1, and 0 for the parameters that enter only the dynamics).
    /// `None` for laws with restitution, whose guards and jump maps depend on the parameters
    /// in other ways (sticking force, impact).
    pub(crate) fn guard_param_derivative(
        &self,
        mode: Region,
        param: SweepParam,
        tau: f64,
    ) -> Option<f64> {
        if self.law.law().restitution().is_some() {
            return None;
        }
        let p = &self.params;
        let (s, c) = (p.omega * tau).sin_cos();
        // base_amplitude() is α2 or 0: linear in α2, so its value at α2 = 1 is its derivative
        let unit = p.with(SweepParam::Alpha2, 1.0).base_amplitude();
        let dv = match param {
            SweepParam::Omega => p.base_amplitude() * tau * c,
            SweepParam::Alpha2 => unit * s,
            SweepParam::Alpha5 => 1.0,
            SweepParam::Alpha1 | SweepParam::Alpha3 | SweepParam::Alpha4 | SweepParam::Alpha6 => {
                0.0
            }
        };
        Some(mode.guard_sign() * dv)
    }

    /// Saltation matrix (2N×2N) at an event of region `from` at (τ, z⁻): the generic
    /// [`crate::system::saltation`] of this system. For the linear law on V_T = 0 only the
    /// damper term α6 V̇_T jumps, so S ≠ I whenever α6 > 0.
    pub fn saltation(&self, from: Region, tau: f64, z: &DVector<f64>) -> DMatrix<f64> {
        crate::system::saltation(self, from, tau, z.as_slice()).0
    }
}

/// The free system has no steady state at ω (an undamped natural frequency).
fn no_free_steady_state(omega: f64) -> SimError {
    SimError::out_of_range(
        "drive frequency",
        omega,
        "the free system has no steady state at an undamped natural frequency",
    )
}

//! Taylor coefficients of the cantilever's flow with a nonlinear tip force, by the recurrences
//! of automatic differentiation (Moore, *Interval Analysis*, Prentice-Hall 1966, ch. 11;
//! Griewank & Walther, *Evaluating Derivatives*, 2nd ed., SIAM 2008, §13.2): every quantity of
//! the vector field is carried as its Taylor series in the independent variable, and the
//! coefficient of order k + 1 of the state follows from those of order ≤ k of the field.
//!
//! The equations are those of [`crate::model`] with region I's matrices (the nonlinear laws
//! add their tip force to the free flight's equations):
//!
//! ä = −M⁻¹K a − M⁻¹C ȧ + M⁻¹F^I(τ) + M⁻¹φ F_c,  V_T = φᵀa + α2_b sin Ωτ + α5 (eq. 8),
//!
//! with α2_b the base amplitude of V_T (α2 for the beam, 0 for the point mass) and
//! F^I = f₀ + f_s sin Ωτ + f_c cos Ωτ (eq. 14).
//!
//! **Free flight, in τ** ([`Jet::free`]). DMT's van der Waals force F_c = −H̃u², u = 1/d,
//! d = V_T + ã₀ > ã₀ (the reciprocal by u d = 1, [Griewank & Walther, Table 13.2]); the other
//! laws exert no force there. sin Ωτ and cos Ωτ have the closed-form coefficients
//! Ωᵏ/k! sin(Ωτ₀ + kπ/2).
//!
//! **Contact, in the regularising time σ** ([`Jet::contact`]). The Hertz force α4 δ^{3/2}
//! (δ = −V_T) is not analytic where contact begins and ends: with δ ≈ v (τ − τ_c) the solution
//! holds a term (τ − τ_c)^{7/2}, so a series in τ from the contact onset does not converge and
//! steps shrink geometrically towards both ends of the contact (the adaptive integrator's 23
//! steps of a DMT contact of the point-mass probe). With w = √δ and dτ/dσ = 2w the contact
//! flow becomes
//!
//! dτ/dσ = 2w,  dz/dσ = 2w f(τ, z),  dw/dσ = δ̇ = −dV_T/dτ,
//!
//! whose right-hand side is a polynomial in (z, w) and trigonometric in τ: F_c = α4 wδ + α6 δ̇
//! (Hertz), −H̃/ã₀² + α4 wδ + α6 wδ̇ (DMT, Kelvin–Voigt ∝ √δ). w² = δ is a first integral
//! (d(w²)/dσ = 2wδ̇ = dδ/dσ), τ − τ_c ≈ v σ² at the onset (the square-root time of a
//! regularised collision, Stiefel & Scheifele, *Linear and Regular Celestial Mechanics*,
//! Springer 1971, §I.2), and contact ends where w falls through 0 — a simple root, not the
//! double root of δ. sin Ωτ(σ) and cos Ωτ(σ) follow from S′ = Ω C τ′, C′ = −Ω S τ′.
//!
//! **Contact's interior, in τ** ([`Jet::contact_interior`]). Away from the contact's edges
//! (δ ≥ δ_min > 0) the flow is analytic in τ: the state keeps the free flight's linear
//! recurrence plus M⁻¹φ F_c, with w = √δ from w² = δ, w_k = (δ_k − Σ_{0<j<k} w_j w_{k−j})/(2w₀)
//! [Griewank & Walther, Table 13.2], F_c as above, and for DMT's damper ∂F_c/∂δ through
//! q = δ̇/w from w q = δ̇. Two or three products of series per order instead of one per state
//! component in σ; the integrator chooses between the two (`Taylor`'s module docs).
//!
//! **Variational equations.** Φ = ∂z(τ)/∂z(τ₀), Φ′ = JΦ with the rank-one tip-force term
//! J = A + [0; M⁻¹φ](F_V cᵀ + F_V̇ c′ᵀ), c = (φ, 0), c′ = (0, φ), F_V = ∂F_c/∂V_T,
//! F_V̇ = ∂F_c/∂(dV_T/dτ). In σ, dΦ/dσ = 2wJΦ: the Jacobian over fixed times τ₀, τ₁ along the
//! trajectory, reparametrised; 2wF_V = −3α4 δ (− α6 δ̇ for DMT) and 2wF_V̇ = −2α6 w (Hertz),
//! −2α6 δ (DMT) are polynomial, so the √δ singularity of ∂F_c/∂δ at the contact onset
//! (DMT's Kelvin–Voigt term) does not appear.
//!
//! Layout: order-major, the coefficient of order k of the state at `z[k·d .. (k+1)·d]`,
//! d = 2N; of Φ (column-major d×d) at `phi[k·d² .. (k+1)·d²]`.

// the recurrences index several series by the order k and by k − j at once
#![allow(clippy::needless_range_loop)]

use crate::contact::JetLaw as Law;
use crate::model::CantileverModel;
use crate::system::Region;

/// Highest order the series are formed to (tolerances down to 1e-18 need order 22).
pub(crate) const MAX_ORDER: usize = 40;

/// The model's data the recurrences read (see the module docs).
#[derive(Debug, Clone)]
pub(crate) struct Jet {
    n: usize,
    /// −M⁻¹K, row-major N×N.
    ak: Vec<f64>,
    /// −M⁻¹C, row-major N×N.
    ac: Vec<f64>,
    /// M⁻¹f₀, M⁻¹f_s, M⁻¹f_c (the lower halves of b_const, b_sin, b_cos), shape `[N]`.
    b_const: Vec<f64>,
    b_sin: Vec<f64>,
    b_cos: Vec<f64>,
    /// M⁻¹φ, shape `[N]`.
    mphi: Vec<f64>,
    /// φ(1), shape `[N]`.
    phi: Vec<f64>,
    /// α2_b: the base amplitude in V_T.
    base: f64,
    alpha5: f64,
    omega: f64,
    law: Law,
    /// Ωᵏ/k!, k ≤ MAX_ORDER.
    trig_factor: Vec<f64>,
    /// The further components of a multifrequency drive ([`crate::params::DriveComponent`]):
    /// (F̃, ω, θ) of F̃ cos(ωτ + θ) at the tip, and ωᵏ/k! per component (M each).
    components: Vec<(f64, f64, f64)>,
    component_factor: Vec<f64>,
    /// The energy balance's rates ([`CantileverModel::power`]): the Galerkin forcing f_s, f_c
    /// (not M⁻¹-scaled), and the damping C^I_ii (α3 s_i, eq. 12; C^I is diagonal).
    power_sin: Vec<f64>,
    power_cos: Vec<f64>,
    damping: Vec<f64>,
    /// Gauss–Legendre nodes and weights on [−1, 1] of [`Jet::rate_integrals`].
    rate_rule: [(f64, f64); RATE_NODES],
}

/// What the series of a step are formed to ([`Jet::free`], [`Jet::contact`],
/// [`Jet::contact_interior`]): order `p`, and Φ (from Φ(τ₀) = I) when `variational`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Order {
    pub p: usize,
    pub variational: bool,
}

/// Nodes of the Gauss–Legendre rule of the energy balance over a step ([`Jet::rate_integrals`]).
const RATE_NODES: usize = 8;

/// Coefficients per series: orders 0..=MAX_ORDER.
const M: usize = MAX_ORDER + 1;

/// The Taylor coefficients of one step (see the module docs for the layout), and the scratch
/// series the recurrences need, allocated once per integrator.
#[derive(Debug, Clone)]
pub(crate) struct Series {
    /// Order p: coefficients 0..=p are formed.
    pub p: usize,
    /// State dimension d = 2N.
    pub d: usize,
    /// Whether Φ is formed.
    pub variational: bool,
    /// Which flow: free flight or contact.
    pub region: Region,
    /// Whether the series variable is the regularising time σ (a contact step at the
    /// contact's edges) rather than τ − τ₀ (free flight, and a contact step in the contact's
    /// interior, [`Jet::contact_interior`]).
    pub sigma: bool,
    /// Start time τ₀.
    pub t0: f64,
    /// The state's coefficients, M·d (orders 0..=p formed).
    pub z: Vec<f64>,
    /// Φ's coefficients, M·d² (empty without the variational equations).
    pub phi: Vec<f64>,
    /// Contact: τ − τ₀ as a series in σ.
    pub theta: [f64; M],
    /// Contact: w = √δ.
    pub w: [f64; M],
    /// V_T.
    pub v: [f64; M],
    /// The tip force F_c.
    pub f: [f64; M],
    /// The further drive components' tip force F̃(τ) = Σ F̃ cos(ωτ + θ) (0 without them).
    pub fd: [f64; M],
    /// Contact in σ: sin and cos of each component's ωτ(σ) + θ, M per component.
    comp_s: Vec<f64>,
    comp_c: Vec<f64>,
    // scratch series of the recurrences
    /// u and w backwards (`urev[M − 1 − j] = u_j`), so that every product of series is a dot
    /// product of two contiguous slices ([`dot`]).
    urev: [f64; M],
    wrev: [f64; M],
    s: [f64; M],
    c: [f64; M],
    del: [f64; M],
    deld: [f64; M],
    u: [f64; M],
    u2: [f64; M],
    u3: [f64; M],
    fv: [f64; M],
    fvd: [f64; M],
    /// f(τ, z) per order (contact: the factor of 2w), component-major: `g[i·M + k]`, M·d.
    g: Vec<f64>,
    /// AΦ per order, M·d².
    gphi: Vec<f64>,
    /// φᵀ(upper rows of Φ) and φᵀ(lower rows of Φ) per order, M·d each.
    r: Vec<f64>,
    rd: Vec<f64>,
}

impl Default for Series {
    fn default() -> Self {
        Series {
            p: 0,
            d: 0,
            variational: false,
            region: Region::Free,
            sigma: false,
            t0: 0.0,
            z: Vec::new(),
            phi: Vec::new(),
            theta: [0.0; M],
            w: [0.0; M],
            v: [0.0; M],
            f: [0.0; M],
            fd: [0.0; M],
            comp_s: vec![0.0; crate::params::MAX_DRIVE_COMPONENTS * M],
            comp_c: vec![0.0; crate::params::MAX_DRIVE_COMPONENTS * M],
            urev: [0.0; M],
            wrev: [0.0; M],
            s: [0.0; M],
            c: [0.0; M],
            del: [0.0; M],
            deld: [0.0; M],
            u: [0.0; M],
            u2: [0.0; M],
            u3: [0.0; M],
            fv: [0.0; M],
            fvd: [0.0; M],
            g: Vec::new(),
            gphi: Vec::new(),
            r: Vec::new(),
            rd: Vec::new(),
        }
    }
}

/// Σ_j x_j y_j over two slices of one length, in four partial sums (vectorised; the
/// recurrences are latency-bound, and one chain of additions would cost 4 cycles a term).
#[inline(always)]
fn dot(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len().min(y.len());
    let (x, y) = (&x[..n], &y[..n]);
    if n < 4 {
        // the short products over modes (N a constant of the monomorphised recurrences)
        return x.iter().zip(y).map(|(a, b)| a * b).sum();
    }
    let (cx, cy) = (x.chunks_exact(4), y.chunks_exact(4));
    let (rx, ry) = (cx.remainder(), cy.remainder());
    let mut acc = [0.0; 4];
    for (a, b) in cx.zip(cy) {
        for i in 0..4 {
            acc[i] += a[i] * b[i];
        }
    }
    let mut s = (acc[0] + acc[2]) + (acc[1] + acc[3]);
    for (a, b) in rx.iter().zip(ry) {
        s += a * b;
    }
    s
}

/// Σ_{j=0..=k} a_j b_{k−j}, the coefficient of order k of the product of two series, given b
/// backwards (`brev[M − 1 − j] = b_j`): a dot product of contiguous slices.
#[inline(always)]
fn cauchy_rev(a: &[f64; M], brev: &[f64; M], k: usize) -> f64 {
    let k = k.min(M - 1);
    dot(&a[..=k], &brev[M - 1 - k..])
}

/// The number of modes N, a constant of the monomorphised recurrences for small N (the loops
/// over modes unrolled, the slices' bounds known) and a run-time value beyond.
trait Width: Copy {
    fn get(self) -> usize;
}

#[derive(Clone, Copy)]
struct Fixed<const N: usize>;

impl<const N: usize> Width for Fixed<N> {
    #[inline(always)]
    fn get(self) -> usize {
        N
    }
}

#[derive(Clone, Copy)]
struct Runtime(usize);

impl Width for Runtime {
    #[inline(always)]
    fn get(self) -> usize {
        self.0
    }
}

/// `$body` with `$w` the [`Width`] of `$n` modes: fixed for N ≤ 4, else at run time.
macro_rules! with_width {
    ($n:expr, $w:ident => $body:expr) => {
        match $n {
            1 => {
                let $w = Fixed::<1>;
                $body
            }
            2 => {
                let $w = Fixed::<2>;
                $body
            }
            3 => {
                let $w = Fixed::<3>;
                $body
            }
            4 => {
                let $w = Fixed::<4>;
                $body
            }
            n => {
                let $w = Runtime(n);
                $body
            }
        }
    };
}

// the contact flow's recurrences (in σ and in τ), after the macro they use
mod contact;

// the series' accessors and their evaluation by Horner's scheme
mod series;

impl Jet {
    /// Move the sample to the gap α5 = `alpha5` (the only datum of the jet that depends on it:
    /// the law's piece and the free flight's forcing do not).
    pub(crate) fn set_gap(&mut self, alpha5: f64) {
        self.alpha5 = alpha5;
    }

    /// The data of `model`, or `None` for a law the recurrences do not carry (the linear law,
    /// propagated exactly, and the impact law, whose contact is a constraint).
    pub(crate) fn new(model: &CantileverModel) -> Option<Self> {
        let p = model.params();
        // the law's piece of the jet ([`crate::contact::Law::jet`]): the tip force as the
        // recurrences carry it
        let law = model.law().jet(p.alpha4, p.alpha6)?;
        let n = model.modes();
        let free = model.dynamics(Region::Free);
        let mut ak = vec![0.0; n * n];
        let mut ac = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                ak[i * n + j] = free.a[(n + i, j)];
                ac[i * n + j] = free.a[(n + i, n + j)];
            }
        }
        let lower = |v: &nalgebra::DVector<f64>| v.as_slice()[n..].to_vec();
        let omega = p.omega;
        let mut trig_factor = vec![1.0; MAX_ORDER + 1];
        for k in 1..=MAX_ORDER {
            trig_factor[k] = trig_factor[k - 1] * omega / k as f64;
        }
        let components: Vec<(f64, f64, f64)> = p
            .components()
            .map(|c| (c.force, c.ratio() * omega, c.phase))
            .collect();
        let mut component_factor = vec![1.0; components.len() * M];
        for (j, c) in components.iter().enumerate() {
            for k in 1..=MAX_ORDER {
                component_factor[j * M + k] = component_factor[j * M + k - 1] * c.1 / k as f64;
            }
        }
        Some(Jet {
            components,
            component_factor,
            n,
            ak,
            ac,
            b_const: lower(&free.b_const),
            b_sin: lower(&free.b_sin),
            b_cos: lower(&free.b_cos),
            mphi: model.tip_mobility().as_slice().to_vec(),
            phi: model.tip().as_slice().to_vec(),
            base: p.base_amplitude(),
            alpha5: p.alpha5,
            omega,
            law,
            trig_factor,
            power_sin: model
                .galerkin()
                .region(Region::Free)
                .forcing
                .sin
                .as_slice()
                .to_vec(),
            power_cos: model
                .galerkin()
                .region(Region::Free)
                .forcing
                .cos
                .as_slice()
                .to_vec(),
            damping: {
                let c = &model.galerkin().region(Region::Free).damping;
                (0..c.nrows()).map(|i| c[(i, i)]).collect()
            },
            rate_rule: {
                let rule = gauss_quad::legendre::GaussLegendre::new(
                    std::num::NonZeroUsize::new(RATE_NODES).expect("nonzero"),
                );
                let mut nodes = [(0.0, 0.0); RATE_NODES];
                for (o, (x, w)) in nodes.iter_mut().zip(rule.iter()) {
                    *o = (*x, *w);
                }
                nodes
            },
        })
    }

    /// The integrals over [0, `end`] of the series variable of the energy balance's rates of
    /// [`CantileverModel::power`] — [base work, beam dissipation, sample dissipation] — from the
    /// step's series `s`, by the Gauss–Legendre rule of [`RATE_NODES`] nodes in the series'
    /// variable (in contact the rates times dτ/dσ = 2w): the integrands are analytic over the
    /// step with a radius of convergence ρ about 3.5 steps long (the step rule, h ≈ ρ ε^{1/p}), so
    /// 8 nodes integrate them to about (h/2ρ)^{16} ≈ 1e-15 relative (Davis & Rabinowitz, *Methods
    /// of Numerical Integration*, 2nd ed., Academic Press 1984, §4.6). The series are evaluated at
    /// all nodes at once (Horner's scheme over the nodes).
    pub(crate) fn rate_integrals(&self, s: &Series, end: f64) -> [f64; 3] {
        let (n, d, p) = (self.n, s.d, s.p);
        let mut x = [0.0; RATE_NODES];
        for (xg, &(node, _)) in x.iter_mut().zip(&self.rate_rule) {
            *xg = 0.5 * end * (node + 1.0);
        }
        let at = |c: &dyn Fn(usize) -> f64| {
            let mut acc = [0.0; RATE_NODES];
            for k in (0..=p).rev() {
                let ck = c(k);
                for g in 0..RATE_NODES {
                    acc[g] = acc[g] * x[g] + ck;
                }
            }
            acc
        };
        let (sn, cs, f) = (at(&|k| s.s[k]), at(&|k| s.c[k]), at(&|k| s.f[k]));
        // the further drive components' power F̃(τ) Ẇ(1,τ)
        let fd = if self.components.is_empty() {
            [0.0; RATE_NODES]
        } else {
            at(&|k| s.fd[k])
        };
        let bo = self.base * self.omega;
        // Σ_i f_s,i ȧ_i sin Ωτ + (Σ_i f_c,i ȧ_i − α2_b Ω F_c) cos Ωτ, and Σ_i C_ii ȧ_i²
        let mut base = [0.0; RATE_NODES];
        let mut beam = [0.0; RATE_NODES];
        for g in 0..RATE_NODES {
            base[g] = -bo * f[g] * cs[g];
        }
        for i in 0..n {
            let ad = at(&|k| s.z[k * d + n + i]);
            for g in 0..RATE_NODES {
                base[g] += ad[g]
                    * (self.power_sin[i] * sn[g] + self.power_cos[i] * cs[g] + self.phi[i] * fd[g]);
                beam[g] += self.damping[i] * ad[g] * ad[g];
            }
        }
        let mut sample = [0.0; RATE_NODES];
        if s.region == Region::Contact {
            // F_d δ̇ — α6 δ̇² (Hertz), α6 w δ̇² (DMT) — and in σ every rate times dτ/dσ = 2w
            let (w, rate) = (at(&|k| s.w[k]), at(&|k| s.deld[k]));
            for g in 0..RATE_NODES {
                sample[g] = match self.law {
                    Law::Hertz { c, .. } => c * rate[g] * rate[g],
                    Law::Dmt { c, .. } => c * w[g] * rate[g] * rate[g],
                };
                if s.sigma {
                    let dt = 2.0 * w[g];
                    base[g] *= dt;
                    beam[g] *= dt;
                    sample[g] *= dt;
                }
            }
        }
        [base, beam, sample].map(|r| {
            0.5 * end
                * r.iter()
                    .zip(&self.rate_rule)
                    .map(|(v, &(_, w))| v * w)
                    .sum::<f64>()
        })
    }

    /// The coefficient of order k of V_T = φᵀa + α2_b sin Ωτ + α5 (eq. 8) from those of a
    /// (`a`, N) and of sin Ωτ (`sk`).
    #[inline(always)]
    fn v_t_coefficient(&self, a: &[f64], k: usize, sk: f64) -> f64 {
        dot(&self.phi[..a.len()], a) + self.base * sk + if k == 0 { self.alpha5 } else { 0.0 }
    }

    /// The lower half of f at order k: −M⁻¹K a_k − M⁻¹C ȧ_k + M⁻¹F^I_k + M⁻¹φ F_k into `out`
    /// (N), from the state's coefficient `zk`, the tip force's `f` and the series' forcing
    /// (F^I's const only at order 0, its sin Ωτ and cos Ωτ, and the further drive components'
    /// `fd` added to the tip force).
    #[inline(always)]
    fn lower_field<W: Width>(
        &self,
        w: W,
        zk: &[f64],
        series: &Series,
        k: usize,
        f: f64,
        out: &mut [f64],
    ) {
        let (s, c, f) = (series.s[k], series.c[k], f + series.fd[k]);
        let n = w.get();
        let (a, ad) = zk.split_at(n);
        for i in 0..n {
            let row_k = &self.ak[i * n..(i + 1) * n];
            let row_c = &self.ac[i * n..(i + 1) * n];
            let mut acc = dot(row_k, a) + dot(row_c, ad);
            if k == 0 {
                acc += self.b_const[i];
            }
            out[i] = acc + self.b_sin[i] * s + self.b_cos[i] * c + self.mphi[i] * f;
        }
    }

    /// A (the free flight's state matrix) times the columns of Φ_k (d×d, column-major) into
    /// `out`, and φᵀ of Φ_k's upper and lower rows into `r`, `rd` (d each).
    #[inline(always)]
    fn a_times_phi<W: Width>(
        &self,
        w: W,
        phik: &[f64],
        out: &mut [f64],
        r: &mut [f64],
        rd: &mut [f64],
    ) {
        let n = w.get();
        let d = 2 * n;
        for col in 0..d {
            let x = &phik[col * d..(col + 1) * d];
            let (a, ad) = x.split_at(n);
            r[col] = dot(&self.phi, a);
            rd[col] = dot(&self.phi, ad);
            let o = &mut out[col * d..(col + 1) * d];
            o[..n].copy_from_slice(ad);
            for i in 0..n {
                o[n + i] =
                    dot(&self.ak[i * n..(i + 1) * n], a) + dot(&self.ac[i * n..(i + 1) * n], ad);
            }
        }
    }

    /// sin Ωτ and cos Ωτ's coefficients from (sin Ωτ₀, cos Ωτ₀) = (`sn`, `cs`): the closed
    /// forms Ωᵏ/k! sin(Ωτ₀ + kπ/2), Ωᵏ/k! cos(Ωτ₀ + kπ/2), k ≤ `p`.
    fn trig_series(&self, s: &mut Series, sn: f64, cs: f64, p: usize) {
        let quarter = [(sn, cs), (cs, -sn), (-sn, -cs), (-cs, sn)];
        for k in 0..=p {
            let (a, b) = quarter[k & 3];
            let f = self.trig_factor[k];
            s.s[k] = f * a;
            s.c[k] = f * b;
        }
        // the further drive components' F̃ cos(ω(τ₀ + t) + θ) in t: F̃ ωᵏ/k! cos(φ₀ + kπ/2)
        // (without them `fd` keeps its zeros: one jet per integrator)
        if self.components.is_empty() {
            return;
        }
        s.fd[..=p].fill(0.0);
        for (j, &(force, om, theta)) in self.components.iter().enumerate() {
            let (sp, cp) = (om * s.t0 + theta).sin_cos();
            let quarter = [cp, -sp, -cp, sp];
            for k in 0..=p {
                s.fd[k] += force * self.component_factor[j * M + k] * quarter[k & 3];
            }
        }
    }

    /// The components' series in the regularising time σ (a contact step at its edges) at
    /// order 0, from τ₀: sin and cos of ωτ₀ + θ, and F̃(τ₀).
    fn component_sigma_start(&self, s: &mut Series) {
        s.fd[0] = 0.0;
        for (j, &(force, om, theta)) in self.components.iter().enumerate() {
            let (sp, cp) = (om * s.t0 + theta).sin_cos();
            s.comp_s[j * M] = sp;
            s.comp_c[j * M] = cp;
            s.fd[0] += force * cp;
        }
    }

    /// Order k + 1 of the components' series in σ from orders ≤ k and w up to order k
    /// (`wrev`): S′ = ω C τ′, C′ = −ω S τ′ with τ′ = 2w, and F̃ = Σ F̃ C.
    fn component_sigma_next(&self, s: &mut Series, k: usize) {
        let inv = 1.0 / (k + 1) as f64;
        s.fd[k + 1] = 0.0;
        for (j, &(force, om, _)) in self.components.iter().enumerate() {
            let wk = &s.wrev[M - 1 - k..];
            let sn = 2.0 * om * dot(&s.comp_c[j * M..=j * M + k], wk) * inv;
            let cn = -2.0 * om * dot(&s.comp_s[j * M..=j * M + k], wk) * inv;
            s.comp_s[j * M + k + 1] = sn;
            s.comp_c[j * M + k + 1] = cn;
            s.fd[k + 1] += force * cn;
        }
    }

    /// The state's coefficient of order k + 1 in τ from that of order k (`cur`, d, replaced
    /// by it) and the tip force's `f` of order k: (k + 1) z_{k+1} = (ȧ_k, lower field).
    #[inline(always)]
    fn next_order<W: Width>(&self, w: W, s: &mut Series, cur: &mut [f64], k: usize, f: f64) {
        let n = w.get();
        let d = 2 * n;
        let inv = 1.0 / (k + 1) as f64;
        let mut lower = [0.0; crate::params::MAX_MODES];
        let lower = &mut lower[..n];
        self.lower_field(w, cur, s, k, f, lower);
        let mut nxt = [0.0; 2 * crate::params::MAX_MODES];
        let nxt = &mut nxt[..d];
        for i in 0..n {
            nxt[i] = cur[n + i] * inv;
            nxt[n + i] = lower[i] * inv;
        }
        s.z[(k + 1) * d..(k + 2) * d].copy_from_slice(nxt);
        cur.copy_from_slice(nxt);
    }

    /// Φ's coefficient of order k + 1 in τ: (k + 1) Φ_{k+1} = A Φ_k + M⁻¹φ Σ_j r_j with
    /// r_j = F_V,j φᵀΦ_{k−j} + F_V̇,j φᵀΦ̇_{k−j} (module docs), the F_V̇ terms only when `rate`
    /// (the contact; DMT's van der Waals force depends on V_T alone).
    #[inline(always)]
    fn next_phi_order<W: Width>(&self, w: W, s: &mut Series, k: usize, rate: bool) {
        let n = w.get();
        let d = 2 * n;
        let dd = d * d;
        let inv = 1.0 / (k + 1) as f64;
        let (head, tail) = s.phi.split_at_mut((k + 1) * dd);
        let phik = &head[k * dd..];
        let next = &mut tail[..dd];
        let gk = &mut s.gphi[..dd];
        let (r, rd) = (&mut s.r[k * d..(k + 1) * d], &mut s.rd[k * d..(k + 1) * d]);
        self.a_times_phi(w, phik, gk, r, rd);
        for col in 0..d {
            let mut rank = 0.0;
            for j in 0..=k {
                rank += s.fv[j] * s.r[(k - j) * d + col];
            }
            if rate {
                for j in 0..=k {
                    rank += s.fvd[j] * s.rd[(k - j) * d + col];
                }
            }
            let g = &s.gphi[col * d..(col + 1) * d];
            let o = &mut next[col * d..(col + 1) * d];
            for i in 0..n {
                o[i] = g[i] * inv;
                o[n + i] = (g[n + i] + self.mphi[i] * rank) * inv;
            }
        }
    }

    /// The series of the free flight from (τ₀, z₀) in τ − τ₀ to `order` (with Φ(τ₀) = I when
    /// variational), into `s`.
    pub(crate) fn free(&self, s: &mut Series, t0: f64, z0: &[f64], order: Order) {
        if let (1, false, Law::Dmt { h, a0, .. }) = (self.n, order.variational, self.law) {
            return self.free_point_mass_dmt(s, t0, z0, order.p, h, a0);
        }
        with_width!(self.n, w => self.free_w(w, s, t0, z0, order))
    }

    /// [`Jet::free`] of one mode with the DMT law, without the variational equations (the
    /// point-mass model's free flight, the path of `simulate`): the same recurrences as
    /// [`Jet::free_w`] with the state's two coefficients in registers.
    fn free_point_mass_dmt(&self, s: &mut Series, t0: f64, z0: &[f64], p: usize, h: f64, a0: f64) {
        let order = Order {
            p,
            variational: false,
        };
        let (sn, cs) = s.start(order, 2, Region::Free, t0, z0, self.omega);
        self.trig_series(s, sn, cs, p);
        let (phi, ak, ac, m) = (self.phi[0], self.ak[0], self.ac[0], self.mphi[0]);
        let (b0, bs, bc) = (self.b_const[0], self.b_sin[0], self.b_cos[0]);
        let (mut x, mut v) = (z0[0], z0[1]);
        let mut u0 = 0.0;
        for k in 0..=p {
            let vt = phi * x + self.base * s.s[k] + if k == 0 { self.alpha5 } else { 0.0 };
            s.v[k] = vt;
            if k == p {
                break;
            }
            // u = 1/d, d = V_T + ã₀, from u·d = 1; then u²: the newest terms last
            let (uk, u2k) = if k == 0 {
                u0 = 1.0 / (vt + a0);
                (u0, u0 * u0)
            } else {
                // Σ_{j=1..k−1} v_j u_{k−j} with u_{k−1}, the latest, added last
                let old = if k >= 2 {
                    dot(&s.v[2..k], &s.urev[M - k + 1..M - 1]) + s.v[1] * s.u[k - 1]
                } else {
                    0.0
                };
                let uk = -(old + vt * u0) * u0;
                let half = k.div_ceil(2);
                // Σ_{0<j<half} u_j u_{k−j}, u_1 u_{k−1} last
                let old2 = if half >= 2 {
                    dot(&s.u[2..half], &s.urev[M - k + 1..M - 1 - k + half]) + s.u[1] * s.u[k - 1]
                } else {
                    0.0
                };
                let mid = if k.is_multiple_of(2) {
                    s.u[k / 2] * s.u[k / 2]
                } else {
                    0.0
                };
                (uk, 2.0 * (old2 + u0 * uk) + mid)
            };
            s.u[k] = uk;
            s.urev[M - 1 - k] = uk;
            s.u2[k] = u2k;
            let f = -h * u2k;
            s.f[k] = f;
            let inv = 1.0 / (k + 1) as f64;
            let forcing = if k == 0 { b0 } else { 0.0 } + bs * s.s[k] + bc * s.c[k];
            let (xn, vn) = (
                v * inv,
                (ak * x + ac * v + forcing + m * (f + s.fd[k])) * inv,
            );
            s.z[2 * k + 2] = xn;
            s.z[2 * k + 3] = vn;
            (x, v) = (xn, vn);
        }
    }

    fn free_w<W: Width>(&self, w: W, s: &mut Series, t0: f64, z0: &[f64], order: Order) {
        let Order { p, variational } = order;
        let n = w.get();
        let d = 2 * n;
        let (sn, cs) = s.start(order, d, Region::Free, t0, z0, self.omega);
        self.trig_series(s, sn, cs, p);
        // z_k in registers from one order to the next (not reloaded from the series)
        let mut cur = [0.0; 2 * crate::params::MAX_MODES];
        let cur = &mut cur[..d];
        cur.copy_from_slice(z0);
        for k in 0..=p {
            let zk = &*cur;
            let v = self.v_t_coefficient(&zk[..n], k, s.s[k]);
            s.v[k] = v;
            if k == p {
                break;
            }
            // the tip force F_k and ∂F_c/∂V_T
            let f = match self.law {
                Law::Dmt { h, a0, .. } => {
                    // d = V_T + ã₀; u = 1/d from u·d = 1
                    // the newest coefficients (v_k, then u_k) enter last: the terms of the
                    // earlier orders are summed while v_k is formed (the latency chain of one
                    // order is then a few operations long)
                    let u0 = s.u[0];
                    let uk = if k == 0 {
                        1.0 / (s.v[0] + a0)
                    } else {
                        // Σ_{j=1..=k} v_j u_{k−j}, u_{k−j} = urev[M − 1 − k + j]
                        let old = dot(&s.v[1..k], &s.urev[M - k..M - 1]);
                        -(old + v * u0) * u0
                    };
                    s.u[k] = uk;
                    s.urev[M - 1 - k] = uk;
                    s.u2[k] = if k == 0 {
                        uk * uk
                    } else {
                        // 2 Σ_{0<j<k/2} u_j u_{k−j} + u_k²/₂ terms, then 2 u₀ u_k
                        let half = k.div_ceil(2);
                        let old = dot(&s.u[1..half], &s.urev[M - k..M - 1 - k + half]);
                        let mid = if k.is_multiple_of(2) {
                            s.u[k / 2] * s.u[k / 2]
                        } else {
                            0.0
                        };
                        2.0 * (old + s.u[0] * uk) + mid
                    };
                    if variational {
                        s.u3[k] = cauchy_rev(&s.u2, &s.urev, k);
                        s.fv[k] = 2.0 * h * s.u3[k];
                    }
                    -h * s.u2[k]
                }
                Law::Hertz { .. } => {
                    s.fv[k] = 0.0;
                    0.0
                }
            };
            s.f[k] = f;
            self.next_order(w, s, cur, k, f);
            if variational {
                self.next_phi_order(w, s, k, false);
            }
        }
    }
}

#[cfg(test)]
mod tests;

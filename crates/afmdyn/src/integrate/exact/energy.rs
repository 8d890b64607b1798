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
//!
//! **Steps of any length in a modal region** (a span of steps over a stint, `span.rs`; the
//! steps around a switching, to a requested time): with δz(s) = Σ_k Re(u_k q_k e^{λ_k s}) (u_k
//! the weighted plain eigenvectors, `modal.rs`) and Re a Re b = ½ Re(ab + ā b),
//!
//! ∫₀ᵗ δzᵀQδz = ½ Re Σ_jk [(u_jᵀQu_k) q_j q_k E(λ_j + λ_k) + (u_jᵀQū_k) q_j q̄_k E(λ_j + λ̄_k)],
//!
//! E(μ) = ∫₀ᵗ e^{μs} ds = (e^{μt} − 1)/μ; the linear term v(τ)ᵀδz with v = 2Qz_p + l =
//! v₀ + Re(v̂ e^{iΩs}), v̂ = (v_c − i v_s) e^{iΩτ₀}, gives Re Σ_k q_k [(v₀ᵀu_k) E(λ_k) +
//! ½ (v̂ᵀu_k) E(λ_k + iΩ) + ½ (v̂̄ᵀu_k) E(λ_k − iΩ)]; the state-free part z_pᵀQz_p + lᵀz_p + k is
//! a trigonometric polynomial of degree 2 in Ωτ (its five coefficients from five samples),
//! integrated in closed form (from sin, cos nΩτ at the ends, or for |Ωt| < 1 in the product
//! form cos, sin nΩ(τ₀ + t/2) · 2 sin(nΩt/2)/(nΩ), free of their cancellation).
//!
//! Every product of modal coordinates and e^{iΩτ} times E(μ) is the difference of its values
//! at the two ends over μ — q_j q_k E(λ_j + λ_k) = (q_j(t) q_k(t) − q_j q_k)/(λ_j + λ_k),
//! q_k e^{iΩτ₀} E(λ_k + iΩ) = (q_k(t) e^{iΩτ₁} − q_k e^{iΩτ₀})/(λ_k + iΩ), and so on — so given
//! the modal coordinates at both ends (q(t) = e^{Λt} q, which a span has at hand) and sin, cos
//! Ωτ there, a step costs no exponential and no sine. The difference's rounding, a few ulp of
//! the products over |μ|, is a few ulp of |q|² t where |μt| ≥ 1/4; below that, where it would
//! exceed it, E(μ) = t φ₁(μt), φ₁(x) = (eˣ − 1)/x, comes from φ₁'s series instead (in real
//! arithmetic for the real μ = 2 Re λ_k of the lightly damped modes). The values at the ends
//! carry the rounding of a span's grid steps, a few ulp each.

use super::modal::{ModalExp, Modes};
use super::{ExactPropagator, INV_FACT};
use crate::model::RateForm;
use crate::system::Region;
use gauss_quad::legendre::GaussLegendre;
use nalgebra::{Complex, DMatrix, DVector};
use std::num::NonZeroUsize;

type C = Complex<f64>;

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
    /// The modal closed form of steps of any length (module docs), for a modal region.
    modal: Option<ModalRates>,
}

/// The modal coefficients of one region's three rates (module docs), as terms c_r P E(μ) of
/// the rates r = 0, 1, 2 for the modal products P: q_k, q_k e^{iΩτ}, q_k e^{−iΩτ} per
/// representative (the linear term) and q_j q_k, q_j q̄_k per pair j ≤ k (the quadratic one).
/// Q is symmetric, so u_jᵀQu_k and E(λ_j + λ_k) are symmetric in (j, k), and the (k, j) term
/// of the second sum is the conjugate of the (j, k) one (u_kᵀQū_j = conj(u_jᵀQū_k),
/// E(λ_k + λ̄_j) = conj(E(λ_j + λ̄_k))): each sum is its diagonal plus twice the real part over
/// j < k. The factors 2 and ½ are folded into the coefficients.
#[derive(Debug)]
struct ModalRates {
    /// The linear terms of each representative k: P = q_k, q_k e^{iΩτ}, q_k e^{−iΩτ} with
    /// μ = λ_k, λ_k + iΩ, λ_k − iΩ and c_r = v₀ᵀu_k, ½ (v_c − i v_s)ᵀu_k, ½ (v_c + i v_s)ᵀu_k.
    lin: Vec<[Term; 3]>,
    /// The quadratic terms of each pair (j, k), j ≤ k: P = q_j q_k, q_j q̄_k with μ = λ_j + λ_k,
    /// λ_j + λ̄_k and c_r = ½ u_jᵀQu_k, ½ u_jᵀQū_k (twice that for j < k); none where no rate
    /// has a quadratic part.
    quad: Vec<((usize, usize), [Term; 2])>,
    /// The state-free part: k₀ + Σ_{n=1,2} (α_n cos nΩτ + β_n sin nΩτ) as [k₀, α₁, β₁, α₂, β₂].
    trig: [[f64; 5]; 3],
    omega: f64,
}

/// One term of [`ModalRates`]: Σ_r c_r P E(μ) over a step, with c_r/μ kept for the difference
/// form and 1/(16|μ|²), the least t² with |μt| ≥ 1/4, for the choice between the forms.
#[derive(Debug, Clone, Copy)]
struct Term {
    mu: C,
    t2_min: f64,
    coef: [C; 3],
    /// c_r/μ (∞ or NaN for μ = 0, never read: such a term takes the series).
    over_mu: [C; 3],
}

impl Term {
    fn new(mu: C, coef: [C; 3]) -> Self {
        let inv = C::new(1.0, 0.0) / mu;
        Term {
            mu,
            t2_min: 1.0 / (16.0 * mu.norm_sqr()),
            coef,
            over_mu: coef.map(|c| c * inv),
        }
    }

    /// Add Re(c_r P₀ E(μ)) over a step of length t (t2 = t²) to `out`, given P₁ = e^{μt} P₀:
    /// Re(c_r/μ (P₁ − P₀)), or Re(c_r P₀ t φ₁(μt)) below |μt| = 1/4 (module docs).
    #[inline(always)]
    fn add(&self, t: f64, t2: f64, p0: C, p1: C, out: &mut [f64; 3]) {
        let (c, d) = if t2 >= self.t2_min {
            (&self.over_mu, p1 - p0)
        } else {
            (&self.coef, p0 * phi1(self.mu * t) * t)
        };
        for (o, c) in out.iter_mut().zip(c) {
            *o += c.re * d.re - c.im * d.im;
        }
    }
}

/// The two ends of a step [τ₀, τ₀ + t] for [`ModalRates::integrals`]: the modal coordinates of
/// δz at both (q1 = e^{Λt} q0) and (sin, cos) of Ωτ at both.
pub(super) struct RateEnds<'a> {
    pub(super) q0: &'a Modes,
    pub(super) q1: &'a Modes,
    pub(super) trig0: (f64, f64),
    pub(super) trig1: (f64, f64),
    pub(super) t: f64,
}

/// φ₁(x) = (eˣ − 1)/x by its series Σ xⁿ/(n+1)! for |x| < 1/4 (13 terms: 4⁻¹³/14! < 1e-18), in
/// real arithmetic for a real x.
#[cold]
fn phi1(x: C) -> C {
    if x.im == 0.0 {
        let mut sum = INV_FACT[14];
        for f in INV_FACT[1..14].iter().rev() {
            sum = sum * x.re + f;
        }
        return C::new(sum, 0.0);
    }
    let mut sum = C::new(INV_FACT[14], 0.0);
    for f in INV_FACT[1..14].iter().rev() {
        sum = sum * x + f;
    }
    sum
}

/// q_k as a complex number.
#[inline(always)]
fn mode(q: &Modes, k: usize) -> C {
    C::new(q.re[k], q.im[k])
}

impl ModalRates {
    fn new(me: &ModalExp, forms: &[RateForm; 3], fr_zp: [&DVector<f64>; 3], omega: f64) -> Self {
        let r = me.len();
        let dim = me.tv.re.nrows();
        let u: Vec<DVector<C>> = (0..r)
            .map(|k| DVector::from_fn(dim, |i, _| C::new(me.tv.re[(i, k)], me.tv.im[(i, k)])))
            .collect();
        let [p0, ps, pc] = fr_zp;
        let lambda = &me.lambda;
        let iw = C::new(0.0, omega);
        let i = C::new(0.0, 1.0);
        // v = 2Q z_p + l per rate: its constant, cos and sin parts against u_k
        let v: [[Vec<C>; 3]; 3] = std::array::from_fn(|t| {
            let f = &forms[t];
            let v0 = 2.0 * &f.q * p0 + &f.l[0];
            let vc = 2.0 * &f.q * pc + &f.l[2];
            let vs = 2.0 * &f.q * ps + &f.l[1];
            [v0, vc, vs].map(|v| {
                let v = v.map(|x| C::new(x, 0.0));
                u.iter().map(|uk| v.dot(uk)).collect::<Vec<C>>()
            })
        });
        let lin = (0..r)
            .map(|k| {
                let l = lambda[k];
                let c0 = std::array::from_fn(|t| v[t][0][k]);
                let cm = std::array::from_fn(|t| 0.5 * (v[t][1][k] - i * v[t][2][k]));
                let cp = std::array::from_fn(|t| 0.5 * (v[t][1][k] + i * v[t][2][k]));
                [
                    Term::new(l, c0),
                    Term::new(l + iw, cm),
                    Term::new(l - iw, cp),
                ]
            })
            .collect();
        // ½ of the quadratic term, twice for the pairs j < k
        let weight = |j: usize, k: usize| if j < k { 1.0 } else { 0.5 };
        let qs: [DMatrix<C>; 3] = std::array::from_fn(|t| forms[t].q.map(|x| C::new(x, 0.0)));
        let quadratic = forms.iter().any(|f| f.q.amax() > 0.0);
        let quad = (0..r)
            .flat_map(|j| (j..r).map(move |k| (j, k)))
            .filter(|_| quadratic)
            .map(|(j, k)| {
                let w = weight(j, k);
                let ca = std::array::from_fn(|t| u[j].dot(&(&qs[t] * &u[k])) * w);
                let cb = std::array::from_fn(|t| u[j].dot(&(&qs[t] * u[k].map(|c| c.conj()))) * w);
                let (lj, lk) = (lambda[j], lambda[k]);
                (
                    (j, k),
                    [Term::new(lj + lk, ca), Term::new(lj + lk.conj(), cb)],
                )
            })
            .collect();
        // the state-free part sampled at five phases θ_j = 2πj/5 (exact for degree 2)
        let trig = std::array::from_fn(|t| {
            let f = &forms[t];
            let mut coef = [0.0; 5];
            for j in 0..5 {
                let th = 2.0 * std::f64::consts::PI * j as f64 / 5.0;
                let (s, c) = th.sin_cos();
                let zp = p0 + ps * s + pc * c;
                let mut l = vec![0.0; dim];
                f.linear_at((s, c), &mut l);
                let val = (&f.q * &zp).dot(&zp)
                    + l.iter().zip(zp.iter()).map(|(a, b)| a * b).sum::<f64>()
                    + f.constant_at((s, c));
                let (s2, c2) = (2.0 * th).sin_cos();
                for (o, w) in coef
                    .iter_mut()
                    .zip([0.2, 0.4 * c, 0.4 * s, 0.4 * c2, 0.4 * s2])
                {
                    *o += w * val;
                }
            }
            coef
        });
        ModalRates {
            lin,
            quad,
            trig,
            omega,
        }
    }

    /// The three integrals over the step between the ends `e` (module docs).
    fn integrals(&self, e: &RateEnds) -> [f64; 3] {
        let (q0, q1, t) = (e.q0, e.q1, e.t);
        let ((s0, c0), (s1, c1)) = (e.trig0, e.trig1);
        let om = self.omega;
        // ∫cos nΩτ, ∫sin nΩτ (n = 1, 2): from the ends (sin 2x = 2 sin x cos x, cos 2x =
        // cos²x − sin²x), whose rounding costs ε/Ω absolutely; below |Ωt| = 1, where that
        // exceeds ε t, in the product form cos, sin nΩ(τ₀ + t/2) · 2 sin(nΩt/2)/(nΩ) (one sine
        // and cosine of Ωt/2, the middle turned from τ₀ by it)
        let double = |(s, c): (f64, f64)| (2.0 * s * c, c * c - s * s);
        let [ic1, is1, ic2, is2] = if (om * t).abs() >= 1.0 {
            let ((sd0, cd0), (sd1, cd1)) = (double((s0, c0)), double((s1, c1)));
            [
                (s1 - s0) / om,
                (c0 - c1) / om,
                (sd1 - sd0) / (2.0 * om),
                (cd0 - cd1) / (2.0 * om),
            ]
        } else {
            let (sh, ch) = (0.5 * om * t).sin_cos();
            let (sm, cm) = (s0 * ch + c0 * sh, c0 * ch - s0 * sh);
            let (sm2, cm2) = double((sm, cm));
            let (f1, f2) = if om == 0.0 {
                (t, t)
            } else {
                (2.0 * sh / om, 2.0 * sh * ch / om)
            };
            [cm * f1, sm * f1, cm2 * f2, sm2 * f2]
        };
        let mut out = std::array::from_fn(|tr| {
            let k = &self.trig[tr];
            k[0] * t + k[1] * ic1 + k[2] * is1 + k[3] * ic2 + k[4] * is2
        });
        let (rot0, rot1) = (C::new(c0, s0), C::new(c1, s1));
        let t2 = t * t;
        for (k, [l0, lp, lm]) in self.lin.iter().enumerate() {
            let (a, b) = (mode(q0, k), mode(q1, k));
            l0.add(t, t2, a, b, &mut out);
            lp.add(t, t2, a * rot0, b * rot1, &mut out);
            lm.add(t, t2, a * rot0.conj(), b * rot1.conj(), &mut out);
        }
        for &((j, k), [ta, tb]) in &self.quad {
            let (aj, ak, bj, bk) = (mode(q0, j), mode(q0, k), mode(q1, j), mode(q1, k));
            ta.add(t, t2, aj * ak, bj * bk, &mut out);
            tb.add(t, t2, aj * ak.conj(), bj * bk.conj(), &mut out);
        }
        out
    }
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
        let modal = self.spec[r.index()]
            .modal
            .as_ref()
            .map(|me| ModalRates::new(me, &forms, [&fr.p0, &fr.ps, &fr.pc], omega));
        Some(EnergyTable { g, w, c, modal })
    }

    /// [∫ base power, ∫ beam dissipation, ∫ sample dissipation] over the last step: for a whole
    /// grid step from the tables, for any other step in a modal region from the modal closed
    /// form (module docs); `None` for a partial step in a dense region (the caller integrates
    /// the dense output), and for a model without rate forms.
    pub(super) fn last_step_rate_integrals_impl(&mut self) -> Option<[f64; 3]> {
        if self.energy.is_none() {
            let tables = [
                self.energy_table(Region::Free)?,
                self.energy_table(Region::Contact)?,
            ];
            self.energy = Some(std::sync::Arc::new(tables));
        }
        let ri = self.last.region.index();
        let tab = &self.energy.as_ref()?[ri];
        let len = self.tau - self.last.tau0;
        let h = self.grid.h;
        // a whole grid step that ran its full length (a switching inside ends it early)
        let whole = self.last.full && (len - h).abs() <= 8.0 * f64::EPSILON * (h + self.tau.abs());
        if !whole {
            let me = self.spec[ri].modal.as_ref()?;
            let rates = tab.modal.as_ref()?;
            if self.last.span {
                // a span has both ends at hand (`span.rs`)
                let ends = RateEnds {
                    q0: &self.last.q0,
                    q1: &self.last.q1,
                    trig0: self.last.trig0,
                    trig1: self.last.trig1,
                    t: len,
                };
                return Some(rates.integrals(&ends));
            }
            let r = me.len();
            let mut q0 = Modes::ZERO;
            if self.last.modal {
                q0.copy_prefix(&self.last.q0, r);
            } else {
                me.project_plain(self.last.dz0.as_slice(), &mut q0);
            }
            let mut q1 = Modes::ZERO;
            me.factors(len, &mut q1);
            q1.mul_assign(&q0, r);
            let ends = RateEnds {
                q0: &q0,
                q1: &q1,
                trig0: self.trig_at(self.last.tau0),
                trig1: self.trig_now(),
                t: len,
            };
            return Some(rates.integrals(&ends));
        }
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

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
//! **Steps of any length in a modal region** (those around a switching, to a requested time):
//! with δz(s) = Σ_k Re(u_k q_k e^{λ_k s}) (u_k the weighted plain eigenvectors, `modal.rs`) and
//! Re a Re b = ½ Re(ab + ā b),
//!
//! ∫₀ᵗ δzᵀQδz = ½ Re Σ_jk [(u_jᵀQu_k) q_j q_k E(λ_j + λ_k) + (u_jᵀQū_k) q_j q̄_k E(λ_j + λ̄_k)],
//!
//! E(μ) = ∫₀ᵗ e^{μs} ds = t φ₁(μt), φ₁(x) = (eˣ − 1)/x (its series for |x| < 1/4, free of the
//! cancellation); the linear term v(τ)ᵀδz with v = 2Qz_p + l = v₀ + Re(v̂ e^{iΩs}),
//! v̂ = (v_c − i v_s) e^{iΩτ₀}, gives Re Σ_k q_k [(v₀ᵀu_k) E(λ_k) + ½ (v̂ᵀu_k) E(λ_k + iΩ) +
//! ½ (v̂̄ᵀu_k) E(λ_k − iΩ)]; the state-free part z_pᵀQz_p + lᵀz_p + k is a trigonometric
//! polynomial of degree 2 in Ωτ (its five coefficients from five samples), integrated in closed
//! form.

use super::modal::{ModalExp, Modes};
use super::ExactPropagator;
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

/// The modal coefficients of one region's three rates (module docs): r representatives.
#[derive(Debug)]
struct ModalRates {
    /// u_jᵀQu_k and u_jᵀQū_k, r×r row-major, per rate (empty where Q = 0).
    a: [Vec<C>; 3],
    b: [Vec<C>; 3],
    /// v₀ᵀu_k, v_cᵀu_k, v_sᵀu_k per rate (r each).
    p: [[Vec<C>; 3]; 3],
    /// The state-free part: k₀ + Σ_{n=1,2} (α_n cos nΩτ + β_n sin nΩτ) as [k₀, α₁, β₁, α₂, β₂].
    trig: [[f64; 5]; 3],
    /// λ_k.
    lambda: Vec<C>,
}

/// The factors of [`ModalRates::integrals`] that depend on the step length t alone — the
/// integrals E(λ_j + λ_k), E(λ_j + λ̄_k) and E(λ_k), E(λ_k ± iΩ) — kept for the last (region,
/// t, Ω): a run of equal steps (samples between grid points, every step of a recorded period)
/// computes their exponentials once, not at every step.
#[derive(Debug, Clone, Default)]
pub(super) struct RateCache {
    key: Option<(usize, u64, u64)>,
    ejk: Vec<(C, C)>,
    ek: Vec<[C; 3]>,
}

/// ∫₀ᵗ e^{μs} ds = t φ₁(μt), φ₁(x) = (eˣ − 1)/x, given e^{μt} = `exp_mt`: by φ₁'s series
/// below |μt| = 1/4 (13 terms: 4⁻¹³/14! < 1e-18), where eˣ − 1 would cancel, else directly.
fn integral_exp(mu: C, t: f64, exp_mt: C) -> C {
    let x = mu * t;
    if x.norm_sqr() < 0.0625 {
        let (mut term, mut sum) = (C::new(1.0, 0.0), C::new(1.0, 0.0));
        for n in 2..=14 {
            term = term * x / n as f64;
            sum += term;
        }
        sum * t
    } else {
        (exp_mt - 1.0) / mu
    }
}

impl ModalRates {
    fn new(me: &ModalExp, forms: &[RateForm; 3], fr_zp: [&DVector<f64>; 3]) -> Self {
        let r = me.len();
        let dim = me.tv.re.nrows();
        let u: Vec<DVector<C>> = (0..r)
            .map(|k| DVector::from_fn(dim, |i, _| C::new(me.tv.re[(i, k)], me.tv.im[(i, k)])))
            .collect();
        let [p0, ps, pc] = fr_zp;
        let cq = |q: &DMatrix<f64>| q.map(|x| C::new(x, 0.0));
        let a = std::array::from_fn(|t| {
            let q = cq(&forms[t].q);
            if forms[t].q.amax() == 0.0 {
                return Vec::new();
            }
            (0..r * r)
                .map(|jk| u[jk / r].dot(&(&q * &u[jk % r])))
                .collect()
        });
        let b = std::array::from_fn(|t| {
            let q = cq(&forms[t].q);
            if forms[t].q.amax() == 0.0 {
                return Vec::new();
            }
            (0..r * r)
                .map(|jk| u[jk / r].dot(&(&q * u[jk % r].map(|c| c.conj()))))
                .collect()
        });
        let p = std::array::from_fn(|t| {
            let f = &forms[t];
            // v = 2Q z_p + l: constant, cos and sin parts
            let v0 = 2.0 * &f.q * p0 + &f.l[0];
            let vc = 2.0 * &f.q * pc + &f.l[2];
            let vs = 2.0 * &f.q * ps + &f.l[1];
            [v0, vc, vs].map(|v| {
                let v = v.map(|x| C::new(x, 0.0));
                u.iter().map(|uk| v.dot(uk)).collect()
            })
        });
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
            a,
            b,
            p,
            trig,
            lambda: me.lambda.clone(),
        }
    }

    /// The step-length factors of [`Self::integrals`] for (region `ri`, t, Ω) in `cache`,
    /// computed unless they are there already.
    fn step_factors(&self, ri: usize, t: f64, omega: f64, cache: &mut RateCache) {
        let key = (ri, t.to_bits(), omega.to_bits());
        if cache.key == Some(key) {
            return;
        }
        let r = self.lambda.len();
        let iw = C::new(0.0, omega);
        // e^{λ_k t} and e^{±iΩt}: the exponentials of the sums below are their products
        let f: Vec<C> = self.lambda.iter().map(|&l| (l * t).exp()).collect();
        let (wp, wm) = {
            let g = C::from_polar(1.0, omega * t);
            (g, g.conj())
        };
        // E(λ_j + λ_k), E(λ_j + λ̄_k) (shared by the rates)
        cache.ejk.clear();
        if self.a.iter().any(|a| !a.is_empty()) {
            cache.ejk.extend((0..r * r).map(|jk| {
                let (j, k) = (jk / r, jk % r);
                let (lj, lk) = (self.lambda[j], self.lambda[k]);
                (
                    integral_exp(lj + lk, t, f[j] * f[k]),
                    integral_exp(lj + lk.conj(), t, f[j] * f[k].conj()),
                )
            }));
        }
        cache.ek.clear();
        cache.ek.extend((0..r).map(|k| {
            let l = self.lambda[k];
            [
                integral_exp(l, t, f[k]),
                integral_exp(l + iw, t, f[k] * wp),
                integral_exp(l - iw, t, f[k] * wm),
            ]
        }));
        cache.key = Some(key);
    }

    /// The three integrals over [τ₀, τ₀ + t] from the modal coordinates q of δz(τ₀), in
    /// region `ri` (the key of `cache`, which holds the step-length factors).
    fn integrals(
        &self,
        q: &Modes,
        tau0: f64,
        t: f64,
        omega: f64,
        ri: usize,
        cache: &mut RateCache,
    ) -> [f64; 3] {
        let r = self.lambda.len();
        self.step_factors(ri, t, omega, cache);
        let (ejk, ek) = (&cache.ejk, &cache.ek);
        let qk = |k: usize| C::new(q.re[k], q.im[k]);
        let rot = C::from_polar(1.0, omega * tau0);
        // the trigonometric integrals ∫cos nΩτ, ∫sin nΩτ over the step (n = 1, 2), in the
        // product form free of cancellation
        let trig_int = |n: f64| {
            let half = 0.5 * n * omega * t;
            let (sm, cm) = (n * omega * (tau0 + 0.5 * t)).sin_cos();
            let f = if half.abs() < 1e-300 {
                t
            } else {
                2.0 * half.sin() / (n * omega)
            };
            (cm * f, sm * f)
        };
        let (c1, s1) = trig_int(1.0);
        let (c2, s2) = trig_int(2.0);
        std::array::from_fn(|tr| {
            let k = &self.trig[tr];
            let mut out = k[0] * t + k[1] * c1 + k[2] * s1 + k[3] * c2 + k[4] * s2;
            let [p0, pc, ps] = &self.p[tr];
            let mut lin = C::new(0.0, 0.0);
            for kk in 0..r {
                let vh = (pc[kk] - C::new(0.0, 1.0) * ps[kk]) * rot;
                let vb = (pc[kk] + C::new(0.0, 1.0) * ps[kk]) * rot.conj();
                lin += qk(kk) * (p0[kk] * ek[kk][0] + 0.5 * (vh * ek[kk][1] + vb * ek[kk][2]));
            }
            out += lin.re;
            if !self.a[tr].is_empty() {
                let mut quad = C::new(0.0, 0.0);
                for j in 0..r {
                    for kk in 0..r {
                        let (ea, eb) = ejk[j * r + kk];
                        let (qj, qkk) = (qk(j), qk(kk));
                        quad += qj
                            * (self.a[tr][j * r + kk] * qkk * ea
                                + self.b[tr][j * r + kk] * qkk.conj() * eb);
                    }
                }
                out += 0.5 * quad.re;
            }
            out
        })
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
            .map(|me| ModalRates::new(me, &forms, [&fr.p0, &fr.ps, &fr.pc]));
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
            let q0 = if self.last.modal {
                *self.last.q0
            } else {
                let mut q = Modes::ZERO;
                me.project_plain(self.last.dz0.as_slice(), &mut q);
                q
            };
            let omega = self.model.omega();
            let (tau0, cache) = (self.last.tau0, &mut self.rate_cache);
            return Some(rates.integrals(&q0, tau0, len, omega, ri, cache));
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

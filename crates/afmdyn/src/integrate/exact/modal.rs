//! e^{Ã t} in the eigenbasis Ã = V Λ V⁻¹ (complex), with one representative per
//! complex-conjugate pair.
//!
//! Ã is real, so its eigenvalues are real or come in conjugate pairs (λ, λ̄) with eigenvectors
//! (v, v̄), and for a real y the modal coordinates q = V⁻¹y of a pair are conjugate too. Hence
//! y = V q = Σ_k w_k Re(v_k q_k) over the representatives (Im λ_k > 0 with weight w_k = 2, real
//! λ_k with w_k = 1), and e^{Ãt} y = Σ_k w_k Re(v_k e^{λ_k t} q_k): a grid step costs one
//! complex multiplication per representative (about N), against (2N)² multiply–adds for the
//! dense Φ. Eigenvalues from nalgebra's real Schur form (Golub & Van Loan, *Matrix
//! Computations*, 4th ed., §7.5), eigenvectors by inverse iteration (ibid. §7.6.1). Accepted
//! only when V is well conditioned and the residual ‖ÃV − VΛ‖ is at round-off; otherwise the
//! caller keeps the dense path.

use super::K;
use nalgebra::{Complex, DMatrix, DVector};
use wide::f64x2;

/// Largest state dimension 2N.
pub(super) const MAXD: usize = 2 * crate::params::MAX_MODES;

/// Largest accepted condition number ‖V‖_F ‖V⁻¹‖_F of the eigenvector basis.
pub(crate) const MAX_MODAL_CONDITION: f64 = 1e4;

type C = Complex<f64>;

/// Complex modal values in structure-of-arrays form (real and imaginary parts apart, so that
/// the grid step vectorizes); the first r entries are used.
#[derive(Debug, Clone, Copy)]
pub(super) struct Modes {
    pub(super) re: [f64; MAXD],
    pub(super) im: [f64; MAXD],
}

impl Modes {
    /// All zero.
    pub(super) const ZERO: Modes = Modes {
        re: [0.0; MAXD],
        im: [0.0; MAXD],
    };

    fn from(values: &[C]) -> Modes {
        let mut m = Modes::ZERO;
        for (k, v) in values.iter().enumerate().take(MAXD) {
            m.re[k] = v.re;
            m.im[k] = v.im;
        }
        m
    }

    /// self ← other over the first r entries (the rest is not read by anyone).
    pub(super) fn copy_prefix(&mut self, other: &Modes, r: usize) {
        self.re[..r].copy_from_slice(&other.re[..r]);
        self.im[..r].copy_from_slice(&other.im[..r]);
    }

    /// self ← self ⊙ other elementwise over the first r entries.
    pub(super) fn mul_assign(&mut self, other: &Modes, r: usize) {
        let (re, im) = (&mut self.re[..r], &mut self.im[..r]);
        for (((a, b), c), d) in re
            .iter_mut()
            .zip(im)
            .zip(&other.re[..r])
            .zip(&other.im[..r])
        {
            let (x, y) = (*a, *b);
            *a = x * c - y * d;
            *b = x * d + y * c;
        }
    }
}

/// The first r modes in pairs (lane 0: even k, lane 1: odd k, so that a pair is one vector)
/// and the odd one left over.
fn pairs(x: &[f64; MAXD], r: usize) -> (&[[f64; 2]], &[f64]) {
    x[..r].as_chunks::<2>()
}

/// A complex matrix as its real and imaginary parts (column-major), for vectorizable real
/// arithmetic.
#[derive(Debug, Clone)]
pub(super) struct Split {
    pub(super) re: DMatrix<f64>,
    pub(super) im: DMatrix<f64>,
}

impl Split {
    fn new(m: &DMatrix<C>) -> Split {
        Split {
            re: m.map(|c| c.re),
            im: m.map(|c| c.im),
        }
    }
}

/// The eigendecomposition of one region's Ã (energy coordinates).
#[derive(Debug, Clone)]
pub(super) struct ModalExp {
    /// Representative eigenvalues λ_k (r of them, r ≤ 2N).
    pub(super) lambda: Vec<C>,
    /// w_k v_k, 2N × r (energy coordinates).
    pub(super) v: Split,
    /// w_k T⁻¹ v_k, 2N × r (plain coordinates).
    pub(super) tv: Split,
    /// Rows of V⁻¹ of the representatives, r × 2N.
    pub(super) vinv: Split,
    /// V⁻¹ T of the representatives, r × 2N (plain coordinates to modal ones).
    pub(super) vinv_t: Split,
    /// w_k c̃ᵀv_k and w_k c̃ᵀv_k λ_k: the tip deflection and its rate per unit q_k.
    pub(super) tip: Modes,
    pub(super) tip_dot: Modes,
    /// w_k |c̃ᵀv_k| |λ_k|²: curvature of the tip deflection per unit |q_k|.
    pub(super) tip_lam2: Vec<f64>,
    /// w_k c̃ᵀv_k λ_kⁿ, n = 0..=K + 2 ((K + 3) × r): the tip moments c̃ᵀÃⁿ y per unit q_k.
    pub(super) tip_pow: Split,
    /// w_k |c̃ᵀv_k|: bound on the tip moments per unit |q_k| and |λ_k|ⁿ.
    pub(super) tip_abs: Vec<f64>,
    /// max_k |λ_k|.
    pub(super) lambda_max: f64,
}

impl ModalExp {
    /// Decompose `at` (Ã, 2N×2N) with tip row `ct` (c̃ᵀ) and inverse energy transform `tinv`;
    /// `None` when the basis is ill conditioned or the decomposition inaccurate.
    pub(super) fn new(at: &DMatrix<f64>, ct: &[f64], tinv: &DMatrix<f64>) -> Option<Self> {
        let dim = at.nrows();
        let all: Vec<C> = at.complex_eigenvalues().iter().copied().collect();
        let pairs = all.iter().filter(|l| l.im > 0.0).count();
        let below = all.iter().filter(|l| l.im < 0.0).count();
        let mut lambda: Vec<C> = all.iter().copied().filter(|l| l.im > 0.0).collect();
        lambda.extend(all.iter().copied().filter(|l| l.im == 0.0));
        let r = lambda.len();
        if pairs != below || r + pairs != dim {
            return None;
        }
        let a = at.map(|x| C::new(x, 0.0));
        let scale = at.norm().max(1.0);
        // full basis: representatives, then the conjugates of the pairs
        let mut full = DMatrix::<C>::zeros(dim, dim);
        for (k, &l) in lambda.iter().enumerate() {
            let shift = l + C::new(1e-10 * scale, 1e-10 * scale);
            let lu = (&a - DMatrix::<C>::identity(dim, dim) * shift).lu();
            let mut x = DVector::<C>::from_element(dim, C::new(1.0, 0.3));
            for _ in 0..3 {
                x = lu.solve(&x)?;
                let norm = x.norm();
                if !norm.is_finite() || norm == 0.0 {
                    return None;
                }
                x /= C::new(norm, 0.0);
            }
            full.set_column(k, &x);
            if k < pairs {
                full.set_column(r + k, &x.map(|c| c.conj()));
            }
        }
        let inv = full.clone().try_inverse()?;
        let mut lam_full = lambda.clone();
        lam_full.extend(lambda[..pairs].iter().map(|l| l.conj()));
        let lam = DMatrix::from_diagonal(&DVector::from_vec(lam_full));
        let residual = (&a * &full - &full * lam).norm();
        let cond = full.norm() * inv.norm();
        if !(residual <= 1e-12 * scale && cond <= MAX_MODAL_CONDITION) {
            return None;
        }
        let weight = |k: usize| if k < pairs { 2.0 } else { 1.0 };
        let mut v = full.columns(0, r).into_owned();
        for k in 0..r {
            v.column_mut(k).scale_mut(weight(k));
        }
        let tv = Split::new(&(tinv.map(|x| C::new(x, 0.0)) * &v));
        let vinv = inv.rows(0, r).into_owned();
        let t = tinv.clone().try_inverse()?;
        let vinv_t = Split::new(&(&vinv * t.map(|x| C::new(x, 0.0))));
        let tip: Vec<C> = (0..r)
            .map(|k| v.column(k).iter().zip(ct).map(|(vi, &c)| vi * c).sum::<C>())
            .collect();
        let tip_dot: Vec<C> = tip.iter().zip(&lambda).map(|(t, l)| t * l).collect();
        let tip_lam2 = tip
            .iter()
            .zip(&lambda)
            .map(|(t, l)| t.norm() * l.norm_sqr())
            .collect();
        let tip_pow = DMatrix::from_fn(K + 3, r, |n, k| tip[k] * lambda[k].powi(n as i32));
        let tip_abs = tip.iter().map(|t| t.norm()).collect();
        let lambda_max = lambda.iter().map(|l| l.norm()).fold(0.0, f64::max);
        let (tip, tip_dot) = (Modes::from(&tip), Modes::from(&tip_dot));
        Some(ModalExp {
            lambda,
            v: Split::new(&v),
            tv,
            vinv: Split::new(&vinv),
            vinv_t,
            tip,
            tip_dot,
            tip_lam2,
            tip_pow: Split::new(&tip_pow),
            tip_abs,
            lambda_max,
        })
    }

    /// Number of representatives r.
    pub(super) fn len(&self) -> usize {
        self.lambda.len()
    }

    /// q = V⁻¹ y (representatives).
    pub(super) fn project(&self, y: &[f64], q: &mut Modes) {
        Self::apply_rows(&self.vinv, y, q);
    }

    /// q = V⁻¹ T δz (representatives) from plain coordinates δz.
    pub(super) fn project_plain(&self, dz: &[f64], q: &mut Modes) {
        Self::apply_rows(&self.vinv_t, dz, q);
    }

    /// q = B x for an r × 2N complex `rows` B and a real x, column by column.
    fn apply_rows(rows: &Split, x: &[f64], q: &mut Modes) {
        let r = rows.re.nrows();
        let (qr, qi) = (&mut q.re[..r], &mut q.im[..r]);
        qr.fill(0.0);
        qi.fill(0.0);
        let cols = rows.re.as_slice().chunks_exact(r.max(1));
        let cols = cols.zip(rows.im.as_slice().chunks_exact(r.max(1)));
        for ((cr, ci), &xj) in cols.zip(x) {
            for (((a, b), vr), vi) in qr.iter_mut().zip(qi.iter_mut()).zip(cr).zip(ci) {
                *a += vr * xj;
                *b += vi * xj;
            }
        }
    }

    /// out = Σ_k Re(b_k q_k) over the r columns b_k of `basis` (w_k v_k or w_k T⁻¹v_k), added
    /// to `out` when `accumulate`.
    pub(super) fn expand(basis: &Split, q: &Modes, out: &mut [f64], accumulate: bool) {
        if !accumulate {
            out.fill(0.0);
        }
        let n = out.len().max(1);
        let r = basis.re.ncols();
        let cols = basis.re.as_slice().chunks_exact(n);
        let cols = cols.zip(basis.im.as_slice().chunks_exact(n));
        for ((cr, ci), (qr, qi)) in cols.zip(q.re[..r].iter().zip(&q.im[..r])) {
            for ((o, br), bi) in out.iter_mut().zip(cr).zip(ci) {
                *o += br * qr - bi * qi;
            }
        }
    }

    /// out += Σ_k Re(b_k e^{λ_k t} q_k) over the columns b_k = w_k T⁻¹v_k of `tv`: the
    /// homogeneous part in plain coordinates t after modal coordinates q, without forming
    /// e^{Λt} q (the products of [`Modes::mul_assign`] and the sums of [`ModalExp::expand`], in
    /// the same order).
    pub(super) fn expand_advanced(&self, q: &Modes, t: f64, out: &mut [f64]) {
        let n = out.len().max(1);
        let cols = self.tv.re.as_slice().chunks_exact(n);
        let cols = cols.zip(self.tv.im.as_slice().chunks_exact(n));
        for (k, ((cr, ci), l)) in cols.zip(&self.lambda).enumerate() {
            let mag = (l.re * t).exp();
            let (s, c) = (l.im * t).sin_cos();
            let (fr, fi) = (mag * c, mag * s);
            let (qr, qi) = (fr * q.re[k] - fi * q.im[k], fr * q.im[k] + fi * q.re[k]);
            for ((o, br), bi) in out.iter_mut().zip(cr).zip(ci) {
                *o += br * qr - bi * qi;
            }
        }
    }

    /// e^{A t} in plain coordinates, T⁻¹ V e^{Λt} V⁻¹ T = Σ_k w_k Re((T⁻¹v_k) e^{λ_k t} (V⁻¹T)_k),
    /// into `out` (2N×2N) column by column, without allocating.
    pub(super) fn transition_plain_into(&self, t: f64, out: &mut DMatrix<f64>) {
        let (dim, r) = (self.tv.re.nrows(), self.len());
        let mut f = Modes::ZERO;
        self.factors(t, &mut f);
        // column j = Σ_k Re(b_k q_k), q_k = (V⁻¹T)_{kj} e^{λ_k t}, straight into `out` (no
        // per-column modal scratch: a `Modes` is 2·MAXD values to clear)
        let (vr, vi) = (self.vinv_t.re.as_slice(), self.vinv_t.im.as_slice());
        let (br, bi) = (self.tv.re.as_slice(), self.tv.im.as_slice());
        for (j, col) in out.as_mut_slice().chunks_exact_mut(dim).enumerate() {
            col.fill(0.0);
            for k in 0..r {
                let (a, b) = (vr[j * r + k], vi[j * r + k]);
                let qr = a * f.re[k] - b * f.im[k];
                let qi = a * f.im[k] + b * f.re[k];
                let (cr, ci) = (&br[k * dim..(k + 1) * dim], &bi[k * dim..(k + 1) * dim]);
                for ((o, x), y) in col.iter_mut().zip(cr).zip(ci) {
                    *o += x * qr - y * qi;
                }
            }
        }
    }

    /// e^{λ_k t} for every representative.
    pub(super) fn factors(&self, t: f64, out: &mut Modes) {
        for (k, l) in self.lambda.iter().enumerate() {
            let mag = (l.re * t).exp();
            let (s, c) = (l.im * t).sin_cos();
            out.re[k] = mag * c;
            out.im[k] = mag * s;
        }
    }

    /// out = e^{Ã t} y0 (real).
    pub(super) fn apply(&self, y0: &[f64], t: f64, out: &mut [f64]) {
        let mut q = Modes::ZERO;
        let mut f = Modes::ZERO;
        self.project(y0, &mut q);
        self.factors(t, &mut f);
        q.mul_assign(&f, self.len());
        Self::expand(&self.v, &q, out, false);
    }

    /// One step of the modal coordinates into `out`: out = f ⊙ q (f = e^{λ_k t}, the product of
    /// [`Modes::mul_assign`]); returns the tip deflection and rate of the homogeneous part at
    /// the end, Σ Re(w c̃ᵀv out) and Σ Re(w c̃ᵀv λ out), each in two interleaved partial sums
    /// (even k, odd k; the batched step of `exact/batch.rs` sums in the same order). One pass
    /// over the modes, taken in pairs so that a pair is one vector.
    pub(super) fn advance_into(&self, q: &Modes, f: &Modes, out: &mut Modes) -> (f64, f64) {
        let r = self.len();
        let (tip, tip_dot) = (&self.tip, &self.tip_dot);
        let ((qr, qr1), (qi, qi1)) = (pairs(&q.re, r), pairs(&q.im, r));
        let ((fr, fr1), (fi, fi1)) = (pairs(&f.re, r), pairs(&f.im, r));
        let ((tr, tr1), (ti, ti1)) = (pairs(&tip.re, r), pairs(&tip.im, r));
        let ((dr, dr1), (di, di1)) = (pairs(&tip_dot.re, r), pairs(&tip_dot.im, r));
        let (or, or1) = out.re[..r].split_at_mut(r & !1);
        let (oim, oi1) = out.im[..r].split_at_mut(r & !1);
        let (or, oim) = (or.as_chunks_mut::<2>().0, oim.as_chunks_mut::<2>().0);
        // explicit two-lane vectors: left to itself the compiler pairs (w, ẇ) of one mode
        // instead of two modes, with shuffles in every iteration (the same operations in the
        // same order, so the same values)
        let (mut w2, mut d2) = (f64x2::ZERO, f64x2::ZERO);
        for k in 0..qr.len() {
            let (x, y) = (f64x2::from(qr[k]), f64x2::from(qi[k]));
            let (c, s) = (f64x2::from(fr[k]), f64x2::from(fi[k]));
            let (a, b) = (x * c - y * s, x * s + y * c);
            or[k] = a.to_array();
            oim[k] = b.to_array();
            w2 += f64x2::from(tr[k]) * a - f64x2::from(ti[k]) * b;
            d2 += f64x2::from(dr[k]) * a - f64x2::from(di[k]) * b;
        }
        let (mut w, mut d) = (w2.to_array(), d2.to_array());
        if let (Some(&x), Some(&y)) = (qr1.first(), qi1.first()) {
            let (c, s) = (fr1[0], fi1[0]);
            let (a, b) = (x * c - y * s, x * s + y * c);
            or1[0] = a;
            oi1[0] = b;
            w[0] += tr1[0] * a - ti1[0] * b;
            d[0] += dr1[0] * a - di1[0] * b;
        }
        (w[0] + w[1], d[0] + d[1])
    }

    /// The tip deflection and rate of the homogeneous part y = V q: Σ_k Re(w_k c̃ᵀv_k q_k) and
    /// Σ_k Re(w_k c̃ᵀv_k λ_k q_k) — the sums of [`ModalExp::advance_into`] without the step, in
    /// its order (two interleaved partial sums over even and odd k), so that after a step
    /// they are its returned values bit for bit.
    pub(super) fn tip_of(&self, q: &Modes) -> (f64, f64) {
        let r = self.len();
        let (tip, tip_dot) = (&self.tip, &self.tip_dot);
        let ((qr, qr1), (qi, qi1)) = (pairs(&q.re, r), pairs(&q.im, r));
        let ((tr, tr1), (ti, ti1)) = (pairs(&tip.re, r), pairs(&tip.im, r));
        let ((dr, dr1), (di, di1)) = (pairs(&tip_dot.re, r), pairs(&tip_dot.im, r));
        let (mut w2, mut d2) = (f64x2::ZERO, f64x2::ZERO);
        for k in 0..qr.len() {
            let (a, b) = (f64x2::from(qr[k]), f64x2::from(qi[k]));
            w2 += f64x2::from(tr[k]) * a - f64x2::from(ti[k]) * b;
            d2 += f64x2::from(dr[k]) * a - f64x2::from(di[k]) * b;
        }
        let (mut w, mut d) = (w2.to_array(), d2.to_array());
        if let (Some(&a), Some(&b)) = (qr1.first(), qi1.first()) {
            w[0] += tr1[0] * a - ti1[0] * b;
            d[0] += dr1[0] * a - di1[0] * b;
        }
        (w[0] + w[1], d[0] + d[1])
    }

    /// The tip moments mo[n] = c̃ᵀÃⁿ y = Σ_k Re(w_k c̃ᵀv_k λ_kⁿ q_k) of y = V q (n = 0..=K + 2),
    /// and Σ_k w_k |c̃ᵀv_k| |q_k|, which bounds |mo[n]| / max_k |λ_k|ⁿ.
    pub(super) fn moments(&self, q: &Modes, mo: &mut [f64; K + 3]) -> f64 {
        *mo = [0.0; K + 3];
        let (cols_re, _) = self.tip_pow.re.as_slice().as_chunks::<{ K + 3 }>();
        let (cols_im, _) = self.tip_pow.im.as_slice().as_chunks::<{ K + 3 }>();
        let mut amp = 0.0;
        for (k, ((pr, pi), w)) in cols_re.iter().zip(cols_im).zip(&self.tip_abs).enumerate() {
            let (a, b) = (q.re[k], q.im[k]);
            for n in 0..K + 3 {
                mo[n] += pr[n] * a - pi[n] * b;
            }
            amp += w * (a * a + b * b).sqrt();
        }
        amp
    }

    /// Σ_k w_k |c̃ᵀv_k| |λ_k|² |q_k|: bounds |W_hom''| for all later times (Re λ_k ≤ 0).
    pub(super) fn curvature(&self, q: &Modes) -> f64 {
        let r = self.len();
        let parts = q.re[..r].iter().zip(&q.im[..r]).zip(&self.tip_lam2);
        parts.map(|((a, b), w)| (a * a + b * b).sqrt() * w).sum()
    }
}

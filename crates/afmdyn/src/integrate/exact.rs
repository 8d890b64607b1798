//! Exact propagation of the piecewise-linear model with located switchings.
//!
//! Between switchings each region is linear and time-invariant with constant plus harmonic
//! forcing (eq. 10), so with δz = z − z_p(τ) (z_p the periodic particular solution)
//!
//! z(τ + t) = z_p(τ + t) + e^{A_s t} δz(τ).
//!
//! **Grid.** The drive period T is split into m sub-steps h = T/m with ‖Ã_s‖₂ h ≤ θ, where
//! Ã_s = T_s A_s T_s⁻¹ is A_s in energy coordinates y = (L_Kᵀ a, L_Mᵀ ȧ) (K_s = L_K L_Kᵀ,
//! M = L_M L_Mᵀ). Φ_s = e^{A_s h} and z_p at the grid points are precomputed, so a step costs one
//! 2N×2N matrix–vector product. Partial steps (after a switching, to a requested time) use the
//! Taylor series of e^{Ã t} y, which converges fast because ‖Ã t‖ ≤ θ.
//!
//! **Switching detection** on the gap g = ±V_T (eq. 8; + in region I, − in region II) is rigorous:
//! in energy coordinates the homogeneous flow does not increase ‖y‖ (Ã + Ãᵀ ⪯ 0 since C ⪰ 0),
//! so |g''| ≤ ‖Ãᵀ² c̃‖ ‖y(τ_entry)‖ + Ω²|V_p| bounds the curvature over the stint. A step is
//! accepted without search when the two parabolas g(a) + g'(a)s − Bs²/2 and
//! g(b) − g'(b)s − Bs²/2 prove g > 0 over it; otherwise the tip motion in the step is expanded as
//! a power series (moments c̃ᵀÃⁿy), the bound is tightened, and a pruned bisection finds the
//! *leftmost* zero — also a dip below V_T = 0 that returns between two grid points (grazing) —
//! which a safeguarded Newton iteration polishes to round-off.
//!
//! **No re-trigger.** Right after a switching g = 0 and g' > 0 in the new region; the search
//! starts where the lower parabola g'(0)s − Bs²/2 is largest, so the same event cannot fire twice.
//! Many switchings in a vanishing time window are reported as [`SimError::Chattering`].

use super::grid::PeriodGrid;
use super::{matvec, Integrator, Step};
use crate::error::SimError;
use crate::galerkin::Region;
use crate::model::CantileverModel;
use nalgebra::{Complex, DMatrix, DVector};
use std::collections::VecDeque;

/// Bound on ‖Ã‖₂ h for the grid step (radians of the fastest mode per step).
pub const THETA: f64 = 4.0;
/// Number of Taylor terms kept in partial steps and tip polynomials (‖Ãt‖ ≤ θ = 4:
/// θ^41/41! ≈ 1e-25, below round-off even after the largest term, θ⁴/4! ≈ 11).
const K: usize = 40;
/// Switchings within [`CHATTER_WINDOW`] of τ that count as chattering.
const CHATTER_COUNT: usize = 64;
/// Time window of the chattering test.
const CHATTER_WINDOW: f64 = 1e-9;

/// e^{Ã t} through the eigendecomposition Ã = V Λ V⁻¹ (complex), for partial steps of arbitrary
/// length: one complex exponential per eigenvalue and two 2N×2N products, against ~30 Taylor
/// terms. Eigenvalues from nalgebra's real Schur form, eigenvectors by inverse iteration. Only
/// used when V is well conditioned (Ã is close to normal in energy coordinates).
#[derive(Debug, Clone)]
struct ModalExp {
    /// |c̃ᵀ v_k| |λ_k|²: curvature of the tip deflection per unit modal amplitude.
    tip_lam2: Vec<f64>,
    lambda: Vec<Complex<f64>>,
    v: DMatrix<Complex<f64>>,
    vinv: DMatrix<Complex<f64>>,
}

impl ModalExp {
    fn new(at: &DMatrix<f64>) -> Option<Self> {
        let dim = at.nrows();
        let lambda: Vec<Complex<f64>> = at.complex_eigenvalues().iter().copied().collect();
        let a = at.map(|x| Complex::new(x, 0.0));
        let scale = at.norm().max(1.0);
        let mut v = DMatrix::<Complex<f64>>::zeros(dim, dim);
        for (k, &l) in lambda.iter().enumerate() {
            let shift = l + Complex::new(1e-10 * scale, 1e-10 * scale);
            let lu = (&a - DMatrix::<Complex<f64>>::identity(dim, dim) * shift).lu();
            let mut x = DVector::<Complex<f64>>::from_element(dim, Complex::new(1.0, 0.3));
            for _ in 0..3 {
                x = lu.solve(&x)?;
                let norm = x.norm();
                if !norm.is_finite() || norm == 0.0 {
                    return None;
                }
                x /= Complex::new(norm, 0.0);
            }
            v.set_column(k, &x);
        }
        let vinv = v.clone().try_inverse()?;
        // accept only an accurate, well-conditioned decomposition
        let lam = DMatrix::from_diagonal(&DVector::from_vec(lambda.clone()));
        let residual = (&a * &v - &v * lam).norm();
        let cond = v.norm() * vinv.norm();
        (residual <= 1e-12 * scale && cond <= 1e4).then_some(ModalExp {
            tip_lam2: vec![0.0; dim],
            lambda,
            v,
            vinv,
        })
    }

    /// out = e^{Ã t} y0 (real). Slices over the column-major storage: nalgebra's element
    /// iterators cost more than the arithmetic at these sizes.
    fn apply(&self, y0: &[f64], t: f64, out: &mut [f64]) {
        let dim = y0.len();
        let mut c = [Complex::new(0.0, 0.0); 2 * crate::params::MAX_MODES];
        let c = &mut c[..dim];
        for (col, &yj) in self.vinv.as_slice().chunks_exact(dim).zip(y0) {
            for (ci, vij) in c.iter_mut().zip(col) {
                ci.re += vij.re * yj;
                ci.im += vij.im * yj;
            }
        }
        for (ci, l) in c.iter_mut().zip(&self.lambda) {
            let mag = (l.re * t).exp();
            let (s, co) = (l.im * t).sin_cos();
            let e = Complex::new(mag * co, mag * s);
            *ci *= e;
        }
        out.fill(0.0);
        for (col, cj) in self.v.as_slice().chunks_exact(dim).zip(c.iter()) {
            for (o, vij) in out.iter_mut().zip(col) {
                *o += vij.re * cj.re - vij.im * cj.im;
            }
        }
    }
}

/// Precomputed data of one region.
#[derive(Debug, Clone)]
struct RegionProp {
    /// Energy transform T_s (2N×2N, block diagonal) and its inverse.
    t: DMatrix<f64>,
    tinv: DMatrix<f64>,
    /// Ã_s = T A T⁻¹.
    at: DMatrix<f64>,
    /// e^{Ã t} by eigendecomposition, when well conditioned.
    modal: Option<ModalExp>,
    /// Φ_s = e^{A_s h} in plain coordinates.
    phi: DMatrix<f64>,
    /// Particular solution z_p(τ) = p0 + ps sin Ωτ + pc cos Ωτ.
    p0: DVector<f64>,
    ps: DVector<f64>,
    pc: DVector<f64>,
    /// z_p at the m + 1 grid points of one period (columns).
    zp_grid: DMatrix<f64>,
    /// Tip part of z_p: W_p = w0 + ws sin + wc cos.
    wp: [f64; 3],
    /// Rows c̃ᵀ Ãⁿ, n = 0..=K+2, (K+3)×2N: tip-deflection moments of the homogeneous part.
    rows: DMatrix<f64>,
    /// ‖c̃ᵀÃ²‖₂.
    kappa2: f64,
    /// Ω² · amplitude of V_p (bound on |V_p''|).
    vp_curv: f64,
    /// 1/n!, n = 0..=K.
    inv_fact: [f64; K + 1],
}

/// The tip motion inside one step as a truncated power series plus the harmonic part.
#[derive(Debug, Clone)]
struct TipPoly {
    tau0: f64,
    /// mo[n] / n!, mo[n+1]/n!, mo[n+2]/n! for n = 0..=K.
    c: [[f64; K + 1]; 3],
    /// Terms kept: the tail beyond is below round-off over the step.
    terms: usize,
    wp: [f64; 3],
    omega: f64,
    alpha2: f64,
    alpha5: f64,
    sigma: f64,
    /// Dead band added to the gap (see [`ExactPropagator`]'s `dead`).
    dead: f64,
    /// Bound on |g''| over the step.
    curv: f64,
}

impl TipPoly {
    fn horner(c: &[f64], t: f64) -> f64 {
        c.iter().rev().fold(0.0, |acc, &x| acc * t + x)
    }
    /// [W, W', W''] of the tip at local time t.
    fn w(&self, t: f64) -> [f64; 3] {
        let (s, c) = (self.omega * (self.tau0 + t)).sin_cos();
        let (w0, ws, wc) = (self.wp[0], self.wp[1], self.wp[2]);
        let om = self.omega;
        [
            Self::horner(&self.c[0][..self.terms], t) + w0 + ws * s + wc * c,
            Self::horner(&self.c[1][..self.terms], t) + om * (ws * c - wc * s),
            Self::horner(&self.c[2][..self.terms], t) - om * om * (ws * s + wc * c),
        ]
    }
    /// Gap g = σ V_T and its derivative at local time t.
    fn g(&self, t: f64) -> (f64, f64) {
        let (s, c) = (self.omega * (self.tau0 + t)).sin_cos();
        let (w0, ws, wc) = (self.wp[0], self.wp[1], self.wp[2]);
        let om = self.omega;
        let w = Self::horner(&self.c[0][..self.terms], t) + w0 + ws * s + wc * c;
        let dw = Self::horner(&self.c[1][..self.terms], t) + om * (ws * c - wc * s);
        let v = w + self.alpha2 * s + self.alpha5;
        let dv = dw + self.alpha2 * om * c;
        (self.sigma * v + self.dead, self.sigma * dv)
    }
}

/// Positive root of g + d s − B s²/2 (∞ when it never vanishes, 0 when g ≤ 0 and d ≤ 0).
fn parabola_root(g: f64, d: f64, b: f64) -> f64 {
    if b <= 0.0 {
        return if d >= 0.0 {
            f64::INFINITY
        } else {
            (g / -d).max(0.0)
        };
    }
    let disc = d * d + 2.0 * b * g;
    if disc < 0.0 {
        return 0.0;
    }
    ((d + disc.sqrt()) / b).max(0.0)
}

/// True when the curvature bound proves g > 0 on the open interval (0, len).
fn certified_positive(ga: f64, da: f64, gb: f64, db: f64, b: f64, len: f64) -> bool {
    gb > 0.0 && parabola_root(ga, da, b) + parabola_root(gb, -db, b) > len
}

struct Search<'a> {
    poly: &'a TipPoly,
}

impl Search<'_> {
    /// Leftmost t in (a, b] with g(t) ≤ 0, given g(a) > 0; None when g > 0 on (a, b].
    fn first(&self, a: f64, ga: (f64, f64), b: f64, gb: (f64, f64), depth: u32) -> Option<f64> {
        if gb.0 <= 0.0 {
            return Some(self.leftmost(a, ga, b, gb, depth));
        }
        let width = b - a;
        if certified_positive(ga.0, ga.1, gb.0, gb.1, self.poly.curv, width)
            || depth > 64
            || width <= 4.0 * f64::EPSILON * (1.0 + self.poly.tau0.abs())
        {
            return None;
        }
        let m = 0.5 * (a + b);
        let gm = self.poly.g(m);
        if gm.0 <= 0.0 {
            return Some(self.leftmost(a, ga, m, gm, depth + 1));
        }
        self.first(a, ga, m, gm, depth + 1)
            .or_else(|| self.first(m, gm, b, gb, depth + 1))
    }

    /// Leftmost zero in [a, b] with g(a) > 0 ≥ g(b).
    fn leftmost(&self, a: f64, ga: (f64, f64), b: f64, gb: (f64, f64), depth: u32) -> f64 {
        let width = b - a;
        let monotone = ga.1 < 0.0 && gb.1 < 0.0 && -(ga.1 + gb.1) > self.poly.curv * width;
        if monotone || depth > 64 || width <= 4.0 * f64::EPSILON * (1.0 + self.poly.tau0.abs()) {
            return self.newton(a, ga.0, b, gb.0);
        }
        let m = 0.5 * (a + b);
        let gm = self.poly.g(m);
        if gm.0 <= 0.0 {
            return self.leftmost(a, ga, m, gm, depth + 1);
        }
        if let Some(t) = self.first(a, ga, m, gm, depth + 1) {
            return t;
        }
        self.leftmost(m, gm, b, gb, depth + 1)
    }

    /// Safeguarded Newton on a bracket with g(lo) > 0 ≥ g(hi) ([`crate::roots`]).
    fn newton(&self, lo: f64, glo: f64, hi: f64, ghi: f64) -> f64 {
        crate::roots::safeguarded_newton(lo, glo, hi, ghi, self.poly.tau0, &mut |t| self.poly.g(t))
    }
}

/// The last step, kept for dense output.
#[derive(Debug, Clone)]
struct LastStep {
    tau0: f64,
    region: Region,
    /// Homogeneous part δz(τ0) in plain coordinates.
    dz0: DVector<f64>,
    /// Whether the step was a whole grid step (its transition matrix is Φ_s).
    full: bool,
}

/// Exact propagator (see the module docs).
#[derive(Debug, Clone)]
pub struct ExactPropagator {
    model: CantileverModel,
    regions: [RegionProp; 2],
    m: usize,
    h: f64,
    period: f64,
    tau: f64,
    z: DVector<f64>,
    region: Region,
    on_grid: Option<i64>,
    /// Bound on |W_hom''| over the current stint (see `curvature_bound`).
    stint_curvature: f64,
    just_switched: bool,
    recent: VecDeque<f64>,
    last: LastStep,
    /// Tip polynomial of the last step, when built.
    poly: Option<Box<TipPoly>>,
    /// V_T and dV_T/dτ at the current state.
    vt: (f64, f64),
    /// Round-off dead band of the switching test: a region is left when V_T passes 0 by more
    /// than this (1e-15 of the displacement scale). A tip resting on the sample with zero force
    /// (V_T = V̇_T = 0, e.g. α2 = α5 = 0 from rest) then stays put instead of chattering; a real
    /// switching is located within dead/|dV_T/dτ| ≈ 1e-14 of V_T = 0.
    dead: f64,
    /// sin Ωτ_k and cos Ωτ_k on the grid of one period (k = 0..=m).
    trig: Vec<(f64, f64)>,
    zb: DVector<f64>,
    buf: [DVector<f64>; 4],
}

fn energy_transform(
    model: &CantileverModel,
    r: Region,
) -> Result<(DMatrix<f64>, DMatrix<f64>), SimError> {
    let n = model.modes();
    let g = model.galerkin().region(r);
    let singular = |what: &'static str| {
        SimError::out_of_range(what, "not positive definite", "needs validated parameters")
    };
    let lk = g
        .stiffness
        .clone()
        .cholesky()
        .ok_or_else(|| singular("stiffness matrix K"))?
        .l();
    let lm = g
        .mass
        .clone()
        .cholesky()
        .ok_or_else(|| singular("mass matrix M"))?
        .l();
    let mut t = DMatrix::zeros(2 * n, 2 * n);
    t.view_mut((0, 0), (n, n)).copy_from(&lk.transpose());
    t.view_mut((n, n), (n, n)).copy_from(&lm.transpose());
    let tinv = t
        .clone()
        .try_inverse()
        .ok_or_else(|| singular("energy transform T"))?;
    Ok((t, tinv))
}

/// Spectral norm (largest singular value).
fn norm2(a: &DMatrix<f64>) -> f64 {
    a.clone().svd(false, false).singular_values.max()
}

impl ExactPropagator {
    /// Build the propagator; the grid has a multiple of `min_steps_per_period` sub-steps per
    /// period, refined until ‖Ã_s‖₂ h ≤ θ in both regions.
    ///
    /// # Panics
    /// When the forced response is singular: Ω exactly at an undamped natural frequency
    /// (α3 = 0 and no contact damping), where no periodic particular solution exists.
    pub fn new(model: &CantileverModel, min_steps_per_period: usize) -> Self {
        Self::try_new(model, min_steps_per_period).expect("forced response exists")
    }

    /// As [`ExactPropagator::new`], with an error instead of a panic.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] for Ω at an undamped resonance (see [`ExactPropagator::new`]);
    /// [`SimError::Unsupported`] for a law that is not affine (only the linear law is).
    pub fn try_new(model: &CantileverModel, min_steps_per_period: usize) -> Result<Self, SimError> {
        if !model.law().is_affine() {
            return Err(SimError::Unsupported {
                integrator: "exact",
                law: model.law().name(),
                hint:
                    "only the linear law is piecewise affine: use --integrator adaptive (or auto)",
            });
        }
        let n = model.modes();
        let dim = 2 * n;
        let omega = model.omega();
        let period = model.period();
        let transforms = [
            energy_transform(model, Region::Free)?,
            energy_transform(model, Region::Contact)?,
        ];
        let ats: Vec<DMatrix<f64>> = [Region::Free, Region::Contact]
            .iter()
            .map(|&r| &transforms[r.index()].0 * &model.dynamics(r).a * &transforms[r.index()].1)
            .collect();
        let rho = ats.iter().map(norm2).fold(0.0, f64::max);
        let base = min_steps_per_period.max(1);
        // budget: the grid of one period, (2N + 2)(m + 1) values, must fit in
        // params::GRID_BUDGET_BYTES; checked in floating point before any allocation
        let need_f = (period * rho / THETA).ceil().max(8.0);
        let m_f = base as f64 * (need_f / base as f64).ceil();
        let bytes = (dim as f64 + 2.0) * (m_f + 1.0) * 8.0;
        if bytes.is_nan() || bytes > crate::params::GRID_BUDGET_BYTES {
            return Err(SimError::Budget {
                what: "exact integrator grid",
                needed: format!(
                    "{m_f:.3e} steps per drive period ({:.0} MiB)",
                    bytes / (1024.0 * 1024.0)
                ),
                budget: "128 MiB".into(),
                hint: "the system is too stiff for its drive period: raise Ω, lower α3, α4, α6 \
                       or N, or lower the samples per period",
            });
        }
        let need = need_f as usize;
        let m = base * need.div_ceil(base);
        let h = period / m as f64;
        let p = *model.params();
        let mut regions = Vec::with_capacity(2);
        for r in [Region::Free, Region::Contact] {
            let (t, tinv) = transforms[r.index()].clone();
            let at = ats[r.index()].clone();
            let d = model.dynamics(r);
            let phi = &tinv * (&at * h).exp() * &t;
            // particular solution: A p0 = −b_const; [[A, ΩI], [−ΩI, A]] (ps, pc) = −(b_sin, b_cos)
            let p0 = d.a.clone().lu().solve(&(-&d.b_const)).ok_or_else(|| {
                SimError::out_of_range("state matrix", "singular", "K must be SPD")
            })?;
            let mut big = DMatrix::zeros(2 * dim, 2 * dim);
            big.view_mut((0, 0), (dim, dim)).copy_from(&d.a);
            big.view_mut((dim, dim), (dim, dim)).copy_from(&d.a);
            for i in 0..dim {
                big[(i, dim + i)] = omega;
                big[(dim + i, i)] = -omega;
            }
            let mut rhs = DVector::zeros(2 * dim);
            rhs.rows_mut(0, dim).copy_from(&(-&d.b_sin));
            rhs.rows_mut(dim, dim).copy_from(&(-&d.b_cos));
            let resonance = || {
                SimError::out_of_range(
                    "omega",
                    omega,
                    "is an undamped natural frequency: no periodic forced response (add damping)",
                )
            };
            let big_norm = big.norm();
            let sol = big.lu().solve(&rhs).ok_or_else(resonance)?;
            // numerically singular (Ω within round-off of an undamped resonance)
            let amplification = sol.norm() * big_norm;
            if rhs.norm() > 0.0 && (amplification.is_nan() || amplification > 1e13 * rhs.norm()) {
                return Err(resonance());
            }
            let ps = sol.rows(0, dim).into_owned();
            let pc = sol.rows(dim, dim).into_owned();
            let mut zp_grid = DMatrix::zeros(dim, m + 1);
            for k in 0..=m {
                let (s, c) = (omega * (k as f64 * h)).sin_cos();
                let col = &p0 + &ps * s + &pc * c;
                zp_grid.set_column(k, &col);
            }
            let tip = model.tip();
            let wp = [
                tip.dot(&p0.rows(0, n)),
                tip.dot(&ps.rows(0, n)),
                tip.dot(&pc.rows(0, n)),
            ];
            // c̃ = T⁻ᵀ c with c = (φ(1), 0); rows c̃ᵀ Ãⁿ
            let mut c = DVector::zeros(dim);
            c.rows_mut(0, n).copy_from(tip);
            let mut row = tinv.transpose() * c;
            let mut rows = DMatrix::zeros(K + 3, dim);
            for k in 0..K + 3 {
                rows.set_row(k, &row.transpose());
                row = at.transpose() * row;
            }
            let kappa2 = rows.row(2).norm();
            let vp_curv = omega * omega * (wp[1] + p.base_amplitude()).hypot(wp[2]);
            let mut modal = ModalExp::new(&at);
            if let Some(me) = &mut modal {
                let ct = rows.row(0).transpose().map(|x| Complex::new(x, 0.0));
                for k in 0..dim {
                    me.tip_lam2[k] = (ct.dot(&me.v.column(k))).norm() * me.lambda[k].norm_sqr();
                }
            }
            regions.push(RegionProp {
                t,
                tinv,
                modal,
                at,
                phi,
                p0,
                ps,
                pc,
                zp_grid,
                wp,
                rows,
                kappa2,
                vp_curv,
                inv_fact: std::array::from_fn(|n| 1.0 / (1..=n).map(|k| k as f64).product::<f64>()),
            });
        }
        let regions: [RegionProp; 2] = regions.try_into().expect("two regions");
        let scale = regions
            .iter()
            .map(|r| r.wp[1].hypot(r.wp[2]) + r.wp[0].abs())
            .fold(0.0, f64::max);
        let dead = 1e-15 * (1.0 + p.alpha5.abs() + p.base_amplitude() + scale);
        let zero = DVector::zeros(dim);
        Ok(ExactPropagator {
            model: model.clone(),
            regions,
            m,
            h,
            period,
            tau: 0.0,
            z: zero.clone(),
            region: Region::Free,
            on_grid: Some(0),
            stint_curvature: 0.0,
            just_switched: true,
            recent: VecDeque::new(),
            last: LastStep {
                tau0: 0.0,
                region: Region::Free,
                dz0: zero.clone(),
                full: false,
            },
            poly: None,
            vt: (0.0, 0.0),
            dead,
            trig: (0..=m)
                .map(|k| (omega * (k as f64 * h)).sin_cos())
                .collect(),
            zb: zero.clone(),
            buf: [zero.clone(), zero.clone(), zero.clone(), zero],
        })
    }

    /// Sub-steps per drive period m.
    pub fn steps_per_period(&self) -> usize {
        self.m
    }

    /// Transition matrix e^{A_s t} of region `r` in plain coordinates (2N×2N), for
    /// 0 ≤ t ≤ one grid step: the precomputed Φ_s when t is the grid step, else
    /// T⁻¹ e^{Ã t} T column by column (eigendecomposition, or the Taylor series).
    pub fn transition(&self, r: Region, t: f64) -> DMatrix<f64> {
        let rp = &self.regions[r.index()];
        if t == self.h {
            return rp.phi.clone();
        }
        let dim = self.z.len();
        let mut e = DMatrix::zeros(dim, dim);
        let (mut yt, mut term, mut tmp) = (
            DVector::zeros(dim),
            DVector::zeros(dim),
            DVector::zeros(dim),
        );
        for j in 0..dim {
            let y0 = rp.t.column(j).into_owned();
            match &rp.modal {
                Some(me) => me.apply(y0.as_slice(), t, yt.as_mut_slice()),
                None => Self::taylor(&rp.at, &y0, t, &mut yt, &mut term, &mut tmp),
            }
            e.set_column(j, &yt);
        }
        &rp.tinv * e
    }

    /// Jacobian ∂z(τ1)/∂z(τ0) of the flow over the last step [τ0, τ1] inside its region
    /// (without the saltation at a switching that ends it), 2N×2N: Φ_s or e^{A_s t}.
    pub fn step_transition(&self) -> DMatrix<f64> {
        let len = self.tau - self.last.tau0;
        // a whole grid step that ended on the grid (a switching would have cut it short)
        if self.last.full && self.on_grid.is_some() {
            return self.regions[self.last.region.index()].phi.clone();
        }
        self.transition(self.last.region, len)
    }

    /// Grid time of global index j ([`PeriodGrid::tau`]).
    fn grid_tau(&self, j: i64) -> f64 {
        PeriodGrid::new(self.period, self.m).tau(j)
    }

    /// Index of the first grid point strictly after τ ([`PeriodGrid::next_index`]).
    fn next_grid(&self, tau: f64) -> i64 {
        PeriodGrid::new(self.period, self.m).next_index(tau)
    }

    fn zp_into(rp: &RegionProp, omega: f64, tau: f64, out: &mut DVector<f64>) {
        let (s, c) = (omega * tau).sin_cos();
        out.copy_from(&rp.p0);
        out.axpy(s, &rp.ps, 1.0);
        out.axpy(c, &rp.pc, 1.0);
    }

    /// y(t) = Σ Ãⁿ y0 tⁿ/n! into `out`.
    fn taylor(
        at: &DMatrix<f64>,
        y0: &DVector<f64>,
        t: f64,
        out: &mut DVector<f64>,
        term: &mut DVector<f64>,
        tmp: &mut DVector<f64>,
    ) {
        out.copy_from(y0);
        term.copy_from(y0);
        let floor = 1e-34 * y0.norm_squared();
        for n in 1..=K {
            matvec(at, term.as_slice(), tmp.as_mut_slice(), t / n as f64, false);
            std::mem::swap(term, tmp);
            *out += &*term;
            if term.norm_squared() <= floor {
                break;
            }
        }
    }

    /// Homogeneous state at local time t of the last step, in plain coordinates, added to z_p.
    fn state_in_last(&mut self, t: f64, out: &mut DVector<f64>) {
        let rp = &self.regions[self.last.region.index()];
        let [y0, yt, term, tmp] = &mut self.buf;
        matvec(
            &rp.t,
            self.last.dz0.as_slice(),
            y0.as_mut_slice(),
            1.0,
            false,
        );
        match &rp.modal {
            Some(me) => me.apply(y0.as_slice(), t, yt.as_mut_slice()),
            None => Self::taylor(&rp.at, y0, t, yt, term, tmp),
        }
        Self::zp_into(rp, self.model.omega(), self.last.tau0 + t, out);
        matvec(&rp.tinv, yt.as_slice(), out.as_mut_slice(), 1.0, true);
    }

    fn build_poly(&self, region: Region, tau0: f64, dz0: &DVector<f64>, len: f64) -> TipPoly {
        let rp = &self.regions[region.index()];
        let mut y0 = [0.0; 2 * crate::params::MAX_MODES];
        let y0 = &mut y0[..dz0.len()];
        matvec(&rp.t, dz0.as_slice(), y0, 1.0, false);
        let mut mo = [0.0; K + 3];
        matvec(&rp.rows, y0, &mut mo, 1.0, false);
        let mut c = [[0.0; K + 1]; 3];
        for (d, row) in c.iter_mut().enumerate() {
            for ((x, m), f) in row.iter_mut().zip(&mo[d..]).zip(&rp.inv_fact) {
                *x = m * f;
            }
        }
        let p = self.model.params();
        let mut lp = [1.0; K + 1];
        for n in 1..=K {
            lp[n] = lp[n - 1] * len;
        }
        let curv = c[2].iter().zip(&lp).map(|(x, l)| x.abs() * l).sum::<f64>() + rp.vp_curv;
        // keep terms until the remaining tail of every series is below round-off over the step
        let size = |n: usize| c.iter().map(|row| row[n].abs()).fold(0.0, f64::max) * lp[n];
        let scale =
            (0..=K).map(size).fold(0.0, f64::max) + rp.wp.iter().map(|x| x.abs()).sum::<f64>();
        let mut terms = K + 1;
        let mut tail = 0.0;
        while terms > 1 {
            tail += size(terms - 1);
            if tail > 1e-18 * scale {
                break;
            }
            terms -= 1;
        }
        TipPoly {
            tau0,
            c,
            terms,
            wp: rp.wp,
            omega: p.omega,
            alpha2: p.base_amplitude(),
            alpha5: p.alpha5,
            sigma: region.guard_sign(),
            dead: self.dead,
            curv,
        }
    }

    /// Bound on |W_hom''| for the whole stint in `region` entered at (τ, z): the smaller of
    /// the energy bound ‖c̃ᵀÃ²‖ ‖y‖ (‖e^{Ãt}‖₂ ≤ 1) and, with the eigendecomposition
    /// y(t) = Σ v_k e^{λ_k t} q_k, the modal bound Σ |c̃ᵀv_k| |λ_k|² |q_k| (Re λ_k ≤ 0).
    fn curvature_bound(&self, region: Region, tau: f64, z: &DVector<f64>) -> f64 {
        let rp = &self.regions[region.index()];
        let mut zp = DVector::zeros(z.len());
        Self::zp_into(rp, self.model.omega(), tau, &mut zp);
        let y = &rp.t * (z - zp);
        let energy = rp.kappa2 * y.norm();
        match &rp.modal {
            Some(me) => {
                let q = &me.vinv * y.map(|x| Complex::new(x, 0.0));
                let modal: f64 = q
                    .iter()
                    .zip(&me.tip_lam2)
                    .map(|(qk, w)| qk.norm() * w)
                    .sum();
                energy.min(modal * (1.0 + 1e-12))
            }
            None => energy,
        }
    }

    fn chatter_check(&mut self, tau: f64) -> Result<(), SimError> {
        self.recent.push_back(tau);
        while self.recent.len() > CHATTER_COUNT {
            self.recent.pop_front();
        }
        if self.recent.len() == CHATTER_COUNT {
            let window = tau - self.recent[0];
            if window < CHATTER_WINDOW {
                return Err(SimError::Chattering {
                    tau,
                    count: CHATTER_COUNT,
                    window,
                });
            }
        }
        Ok(())
    }
}

impl Integrator for ExactPropagator {
    fn model(&self) -> &CantileverModel {
        &self.model
    }
    fn tau(&self) -> f64 {
        self.tau
    }
    fn state(&self) -> &DVector<f64> {
        &self.z
    }
    fn region(&self) -> Region {
        self.region
    }
    fn name(&self) -> &'static str {
        "exact"
    }

    fn reset(&mut self, tau: f64, z: &DVector<f64>) -> Result<(), SimError> {
        let (region, z) = self.model.checked_start(tau, z)?;
        let z = &z;
        self.region = region;
        self.tau = tau;
        self.z.copy_from(z);
        let j = self.next_grid(tau) - 1;
        self.on_grid = (self.grid_tau(j) == tau).then_some(j);
        self.stint_curvature = self.curvature_bound(self.region, tau, z);
        self.just_switched = true;
        self.recent.clear();
        self.last = LastStep {
            tau0: tau,
            region: self.region,
            dz0: DVector::zeros(z.len()),
            full: false,
        };
        self.poly = None;
        self.vt = (self.model.v_t(tau, z), self.model.v_t_dot(tau, z));
        Ok(())
    }

    fn step(&mut self, tau_max: f64) -> Result<Step, SimError> {
        let region = self.region;
        let tau0 = self.tau;
        let omega = self.model.omega();
        let j_next = match self.on_grid {
            Some(j) => j + 1,
            None => self.next_grid(tau0),
        };
        let t_grid = self.grid_tau(j_next);
        let tau_b = t_grid.min(tau_max);
        let len = tau_b - tau0;
        if len <= 0.0 {
            return Ok(Step {
                tau0,
                tau1: tau0,
                region,
                event: None,
            });
        }
        let full = self.on_grid.is_some() && tau_b == t_grid;
        let ri = region.index();
        // homogeneous part at the start, end state into buf[1]
        let mut dz0 = std::mem::take(&mut self.last.dz0);
        let mut z_b = std::mem::take(&mut self.zb);
        if full {
            let k = self.on_grid.expect("on grid").rem_euclid(self.m as i64) as usize;
            let rp = &self.regions[ri];
            let dim = dz0.len();
            let zp = rp.zp_grid.as_slice();
            let (zk, zk1) = (
                &zp[k * dim..(k + 1) * dim],
                &zp[(k + 1) * dim..(k + 2) * dim],
            );
            for ((d, z), p) in dz0.as_mut_slice().iter_mut().zip(self.z.as_slice()).zip(zk) {
                *d = z - p;
            }
            z_b.as_mut_slice().copy_from_slice(zk1);
            matvec(&rp.phi, dz0.as_slice(), z_b.as_mut_slice(), 1.0, true);
        } else {
            let rp = &self.regions[ri];
            Self::zp_into(rp, omega, tau0, &mut dz0);
            dz0.neg_mut();
            dz0 += &self.z;
        }
        self.last.tau0 = tau0;
        self.last.region = region;
        self.last.dz0 = dz0;
        self.last.full = full;
        self.poly = None;
        let vt_b = if full {
            let k = (self.on_grid.expect("on grid").rem_euclid(self.m as i64) + 1) as usize;
            let (s, c) = self.trig[k];
            let p = self.model.params();
            let n = p.modes;
            let tip = self.model.tip().as_slice();
            let zb = z_b.as_slice();
            let dot = |x: &[f64]| tip.iter().zip(x).map(|(a, b)| a * b).sum::<f64>();
            (
                dot(&zb[..n]) + p.base_amplitude() * s + p.alpha5,
                dot(&zb[n..]) + p.base_amplitude() * p.omega * c,
            )
        } else {
            self.state_in_last(len, &mut z_b);
            (self.model.v_t(tau_b, &z_b), self.model.v_t_dot(tau_b, &z_b))
        };
        let sigma = region.guard_sign();
        let mut ga = sigma * self.vt.0 + self.dead;
        let da = sigma * self.vt.1;
        let gb = sigma * vt_b.0 + self.dead;
        let db = sigma * vt_b.1;
        let switched = self.just_switched || ga <= 0.0;
        if switched {
            ga = ga.max(0.0);
        }
        let rp = &self.regions[ri];
        let cheap = self.stint_curvature + rp.vp_curv;
        let mut hit = None;
        if !certified_positive(ga, da, gb, db, cheap, len) {
            let poly = self.build_poly(region, tau0, &self.last.dz0, len);
            let search = Search { poly: &poly };
            // start of the search: after a switching, where the lower parabola peaks
            let mut a = 0.0;
            let mut g_a = (ga, da);
            if switched {
                a = if da > 0.0 && poly.curv > 0.0 {
                    (da / poly.curv).min(0.5 * len)
                } else {
                    (4.0 * f64::EPSILON * (1.0 + tau0.abs())).min(0.5 * len)
                };
                g_a = poly.g(a);
            }
            if g_a.0 <= 0.0 {
                hit = Some(a);
            } else {
                hit = search.first(a, g_a, len, (gb, db), 0);
            }
            self.poly = Some(Box::new(poly));
        }
        self.just_switched = false;
        match hit {
            None => {
                self.zb = z_b;
                std::mem::swap(&mut self.z, &mut self.zb);
                self.tau = tau_b;
                self.vt = vt_b;
                self.on_grid = (tau_b == t_grid).then_some(j_next);
                if let Some(j) = self.on_grid {
                    if j.rem_euclid(self.m as i64) == 0 {
                        let norm = self.z.norm();
                        if norm.is_nan() || norm >= 1e12 {
                            return Err(SimError::Diverged { tau: tau_b, norm });
                        }
                    }
                }
                Ok(Step {
                    tau0,
                    tau1: tau_b,
                    region,
                    event: None,
                })
            }
            Some(t) => {
                self.zb = z_b;
                let mut zs = DVector::zeros(self.z.len());
                self.state_in_last(t, &mut zs);
                let tau_s = tau0 + t;
                let to = region.other();
                let v_t_dot = self.model.v_t_dot(tau_s, &zs);
                self.z.copy_from(&zs);
                self.tau = tau_s;
                self.vt = (self.model.v_t(tau_s, &zs), v_t_dot);
                self.region = to;
                self.on_grid = None;
                self.just_switched = true;
                self.stint_curvature = self.curvature_bound(to, tau_s, &zs);
                self.chatter_check(tau_s)?;
                Ok(Step::switched(&self.model, tau0, region, tau_s, &zs))
            }
        }
    }

    fn dense_tip(&mut self, tau: f64) -> [f64; 3] {
        let t = tau - self.last.tau0;
        if self.poly.is_none() {
            let len = (self.tau - self.last.tau0).max(t);
            let poly = self.build_poly(self.last.region, self.last.tau0, &self.last.dz0, len);
            self.poly = Some(Box::new(poly));
        }
        self.poly.as_ref().expect("built").w(t)
    }

    fn dense_state(&mut self, tau: f64) -> DVector<f64> {
        let mut out = DVector::zeros(self.z.len());
        self.state_in_last(tau - self.last.tau0, &mut out);
        out
    }

    fn last_step_jacobian(&mut self) -> Result<DMatrix<f64>, SimError> {
        Ok(self.step_transition())
    }
}

//! The exponential (Lawson) frame of the adaptive integrator: the linear free flight propagated
//! exactly, only the deviation that the tip force causes integrated by DOP853.
//!
//! For a law with a force in free flight (DMT's van der Waals attraction), every state obeys
//! ż = A_I z + b_I(τ) + u F_c(τ, z) (eq. 10's free region with the law's tip force on the
//! velocity rows, u = [0; M⁻¹φ(1)]; [`CantileverModel::rhs_slice`]). Split z = z_p(τ) + δz with
//! the particular solution z_p of the free flight ([`Forced`]) and write δz in the modal
//! coordinates of A_I, δz = Σ_k w_k Re(T⁻¹v_k q_k) ([`ModalExp`]): q′_k = λ_k q_k + β_k F_c with
//! β = V⁻¹T u. From an anchor (τ_a, q_a) the variation of constants gives
//! q_k(τ) = e^{λ_k s}(q_{a,k} + y_k(τ)), s = τ − τ_a, with
//!
//! y′_k = e^{−λ_k s} β_k F_c(τ, z(τ)),  y(τ_a) = 0,
//!
//! Lawson's transformation (J. D. Lawson, "Generalized Runge–Kutta processes for stable systems
//! with large Lipschitz constants", *SIAM J. Numer. Anal.* 4 (1967) 372–380; Hochbruck &
//! Ostermann, "Exponential integrators", *Acta Numerica* 19 (2010) 209–286, §2.5), which is
//! Encke's method of celestial mechanics for a perturbing force. DOP853 integrates y: its
//! error is proportional to the force and its derivatives along the motion, not to the
//! oscillation of the modes, so the step is set by how fast F_c varies, and between contacts the
//! weak attraction allows steps far longer than the unperturbed oscillation would.
//!
//! **Stage factors.** Each stepper is anchored at its step's start (τ_a = t0), so its stages are
//! at s = c_i h (DOP853's nodes). Step sizes are taken on the ladder h = T·2^{−j/8} (at most
//! 9 % below the size the error control asks for), and for each size on the ladder the
//! factors e^{±λ_k c_i h} and (sin Ωc_i h, cos Ωc_i h) are tabulated once ([`StageTable`]), so
//! a stage costs no exponential or sine: sin Ωτ, cos Ωτ follow by angle addition from the
//! anchor's. Evaluations off the nodes (dense output, a step shortened to land on a time)
//! compute the factors directly.
//!
//! Stepper state `y: [f64; 2r]` as (Re y_0 … Re y_{r−1}, Im y_0 … Im y_{r−1}) over the r modal
//! representatives of A_I (one per conjugate pair, [`ModalExp`]).

use super::forcing::{modal_tip, Forced};
use super::modal::{ModalExp, Modes};
use super::ExactPropagator;
use crate::contact::TipSampleLaw;
use crate::error::SimError;
use crate::integrate::dop853::{Field, C};
use crate::model::CantileverModel;
use crate::system::Region;
use std::sync::{Arc, Mutex};

/// The exact linear free flight of a model and the tip force's input in its modal coordinates
/// (module docs). Built once per integrator.
#[derive(Debug)]
pub(crate) struct LinearFrame {
    /// The model (its law gives F_c).
    model: CantileverModel,
    /// The eigendecomposition of the free flight's Ã_I.
    modal: ModalExp,
    /// The free flight's particular solution z_p.
    forced: Forced,
    /// β = V⁻¹T [0; M⁻¹φ(1)]: the tip force's input per representative.
    beta: Modes,
    /// Number of representatives r.
    r: usize,
    /// The stage tables of recent ladder step sizes, keyed by the bits of h (most recently
    /// made last; at most [`TABLES`]).
    tables: Mutex<Vec<(u64, Arc<StageTable>)>>,
}

impl Clone for LinearFrame {
    fn clone(&self) -> Self {
        LinearFrame {
            model: self.model.clone(),
            modal: self.modal.clone(),
            forced: self.forced.clone(),
            beta: self.beta,
            r: self.r,
            tables: Mutex::new(Vec::new()),
        }
    }
}

/// Stage tables kept per frame (a run uses a few dozen ladder sizes).
const TABLES: usize = 64;

/// Ladder rungs per halving of the step size.
const RUNGS: f64 = 8.0;

/// The factors of the 16 DOP853 nodes for one step size h (module docs): s_i = c_i h,
/// e^{λ_k s_i} and e^{−λ_k s_i} (rows of 4r: re, im, inverse re, inverse im by k), and
/// (sin Ωs_i, cos Ωs_i).
#[derive(Debug)]
pub(crate) struct StageTable {
    s: [f64; 16],
    factors: Vec<f64>,
    trig: [(f64, f64); 16],
}

/// The anchor of one stepper: τ_a, (sin Ωτ_a, cos Ωτ_a), the modal coordinates q_a of
/// z(τ_a) − z_p(τ_a), and the stage table of the step being taken.
#[derive(Debug, Clone)]
pub(crate) struct Anchor {
    tau: f64,
    trig: (f64, f64),
    q: Modes,
    table: Option<Arc<StageTable>>,
}

impl Anchor {
    /// The node factors for a stage at s = τ − τ_a: the table's row when s is one of its
    /// nodes c_i h (to the round-off of forming τ = τ_a + c_i h), else `None`.
    #[inline]
    fn node(&self, s: f64) -> Option<(&[f64], (f64, f64))> {
        let tb = self.table.as_deref()?;
        let tol = 4.0 * f64::EPSILON * (self.tau.abs() + s.abs());
        let i = tb.s.iter().position(|&si| (si - s).abs() <= tol)?;
        let w = tb.factors.len() / 16;
        Some((&tb.factors[i * w..(i + 1) * w], tb.trig[i]))
    }
}

impl LinearFrame {
    /// The frame of `model`'s free flight, or `None` where it has no well-conditioned modal basis
    /// (a defective or ill-conditioned A_I: the plain adaptive integrator is used there).
    ///
    /// # Errors
    /// As [`ExactPropagator::free_flight`] (Ω at an undamped resonance of the free beam, the
    /// grid budget).
    pub(crate) fn new(model: &CantileverModel) -> Result<Option<Self>, SimError> {
        let free = ExactPropagator::free_flight(model, 1)?;
        let Some(modal) = free.spec[0].modal.clone() else {
            return Ok(None);
        };
        let n = model.modes();
        let mut u = vec![0.0; 2 * n];
        u[n..].copy_from_slice(model.tip_mobility().as_slice());
        let mut beta = Modes::ZERO;
        modal.project_plain(&u, &mut beta);
        let r = modal.len();
        Ok(Some(LinearFrame {
            model: model.clone(),
            forced: free.forced[0].clone(),
            modal,
            beta,
            r,
            tables: Mutex::new(Vec::new()),
        }))
    }

    /// Length of the stepper's state, 2r.
    pub(crate) fn dim(&self) -> usize {
        2 * self.r
    }

    /// The largest step size on the ladder T·2^{−j/8} (j ≥ 0) not above `h` (> 0).
    pub(crate) fn ladder(&self, h: f64) -> f64 {
        let t = self.model.period();
        if !(h > 0.0 && h.is_finite()) || h >= t {
            return h.min(t);
        }
        let mut j = ((t / h).log2() * RUNGS).ceil();
        let mut rung = t * (-j / RUNGS).exp2();
        while rung > h {
            j += 1.0;
            rung = t * (-j / RUNGS).exp2();
        }
        rung
    }

    /// Set the stage table of step size `h` in `anchor` (made and kept on the first request
    /// of an `h` on the ladder; made without keeping for other sizes).
    pub(crate) fn use_step(&self, anchor: &mut Anchor, h: f64) {
        if anchor.table.as_ref().is_some_and(|t| t.s[11] == h) {
            return;
        }
        let key = h.to_bits();
        let on_ladder = self.ladder(h) == h;
        if on_ladder {
            if let Ok(tables) = self.tables.lock() {
                if let Some((_, t)) = tables.iter().rev().find(|(k, _)| *k == key) {
                    anchor.table = Some(t.clone());
                    return;
                }
            }
        }
        let table = Arc::new(self.stage_table(h));
        if on_ladder {
            if let Ok(mut tables) = self.tables.lock() {
                if tables.len() >= TABLES {
                    tables.remove(0);
                }
                tables.push((key, table.clone()));
            }
        }
        anchor.table = Some(table);
    }

    /// The factors of the 16 nodes for step size `h`.
    fn stage_table(&self, h: f64) -> StageTable {
        let r = self.r;
        let mut factors = vec![0.0; 16 * 4 * r];
        let mut s = [0.0; 16];
        let mut trig = [(0.0, 1.0); 16];
        for (i, row) in factors.chunks_exact_mut(4 * r).enumerate() {
            s[i] = C[i] * h;
            trig[i] = (self.model.omega() * s[i]).sin_cos();
            for (k, l) in self.modal.lambda.iter().enumerate() {
                let mag = (l.re * s[i]).exp();
                let (sn, cs) = (l.im * s[i]).sin_cos();
                row[4 * k..4 * k + 4].copy_from_slice(&[mag * cs, mag * sn, cs / mag, -sn / mag]);
            }
        }
        StageTable { s, factors, trig }
    }

    /// z_p(τ) into `out` (2N).
    fn particular_into(&self, tau: f64, out: &mut [f64]) {
        ExactPropagator::zp_at(&self.forced, (self.model.omega() * tau).sin_cos(), out);
    }

    /// The anchor at (τ, z): q_a = V⁻¹T (z − z_p(τ)).
    pub(crate) fn anchor(&self, tau: f64, z: &[f64]) -> Anchor {
        let mut dz = [0.0; super::MAXD];
        let dz = &mut dz[..z.len()];
        self.particular_into(tau, dz);
        for (d, zi) in dz.iter_mut().zip(z) {
            *d = zi - *d;
        }
        let mut q = Modes::ZERO;
        self.modal.project_plain(dz, &mut q);
        Anchor {
            tau,
            trig: (self.model.omega() * tau).sin_cos(),
            q,
            table: None,
        }
    }

    /// The plain state z(τ) = z_p(τ) + Σ_k w_k Re(T⁻¹v_k q_k(τ)) of the stepper state `y` at τ
    /// into `z` (2N).
    pub(crate) fn state_into(&self, a: &Anchor, t: f64, y: &[f64], z: &mut [f64]) {
        let r = self.r;
        let mut q = a.q;
        for (k, (yr, yi)) in y[..r].iter().zip(&y[r..2 * r]).enumerate() {
            q.re[k] += yr;
            q.im[k] += yi;
        }
        self.particular_into(t, z);
        self.modal.expand_advanced(&q, t - a.tau, z);
    }

    /// The stepper state with the variational equations, `y: [f64; 2r(1 + 2N)]` as (y, then Y
    /// column by column in y's layout), at τ, in plain coordinates into `out: [f64; 2N + 4N²]`:
    /// z as [`LinearFrame::state_into`], then Φ = ∂z(τ)/∂z(τ_a) = Σ_k w_k Re(T⁻¹v_k e^{λ_k s}
    /// (P + Y)_k), P = V⁻¹T, column-major (Hairer, Nørsett & Wanner, *Solving ODEs I*, §I.14, in
    /// the frame's variables).
    pub(crate) fn plain_into(&self, a: &Anchor, t: f64, y: &[f64], out: &mut [f64]) {
        let (r, d) = (self.r, self.model.dim());
        let (z, phi) = out.split_at_mut(d);
        self.state_into(a, t, &y[..2 * r], z);
        let mut f = Modes::ZERO;
        self.modal.factors(t - a.tau, &mut f);
        let p = &self.modal.vinv_t;
        let (pr, pi) = (p.re.as_slice(), p.im.as_slice());
        let mut q = Modes::ZERO;
        for (j, (col, out)) in y[2 * r..]
            .chunks_exact(2 * r)
            .zip(phi.chunks_exact_mut(d))
            .enumerate()
        {
            let (cr, ci) = col.split_at(r);
            for k in 0..r {
                let (xr, xi) = (pr[j * r + k] + cr[k], pi[j * r + k] + ci[k]);
                q.re[k] = f.re[k] * xr - f.im[k] * xi;
                q.im[k] = f.re[k] * xi + f.im[k] * xr;
            }
            ModalExp::expand(&self.modal.tv, &q, out, false);
        }
    }

    /// Whether steps in `region` with the variational equations may use the frame: not in DMT
    /// contact with Kelvin–Voigt damping (its ∂F_c/∂δ ∋ α6 δ̇/(2√δ) is unbounded at contact
    /// onset; the plain integrator handles it in its tangent coordinates,
    /// [`crate::system::HybridSystem::variational_rhs`]).
    pub(crate) fn variational_in(&self, region: Region) -> bool {
        region == Region::Free || self.model.tip_sample().damping == 0.0
    }

    /// The field y′ of the frame in `region` from `anchor` (module docs).
    pub(crate) fn field<'a>(&'a self, region: Region, anchor: &'a Anchor) -> LawsonField<'a> {
        LawsonField {
            frame: self,
            contact: region == Region::Contact,
            anchor,
        }
    }
}

/// y′_k = e^{−λ_k s} β_k F_c(τ, z) (the module docs' equation) for one region and anchor, with
/// the variational equations Y′ = e^{−Λs} β (∂F_c/∂z) Φ when the state is longer than 2r
/// ([`LinearFrame::plain_into`]).
pub(crate) struct LawsonField<'a> {
    frame: &'a LinearFrame,
    contact: bool,
    anchor: &'a Anchor,
}

impl Field for LawsonField<'_> {
    fn eval(&self, t: f64, y: &[f64], dy: &mut [f64]) {
        let fr = self.frame;
        let r = fr.r;
        let s = t - self.anchor.tau;
        let (yr, yi) = y[..2 * r].split_at(r);
        let (dy, dvar) = dy.split_at_mut(2 * r);
        let (dr, di) = dy.split_at_mut(r);
        let (q0, tip, tip_dot) = (&self.anchor.q, &fr.modal.tip, &fr.modal.tip_dot);
        // e^{λ_k s} (kept for the variational equations)
        let variational = y.len() > 2 * r;
        let mut fac = [[0.0; 2]; super::MAXD];
        // q_k = e^{λ_k s}(q_a + y)_k summed into the homogeneous part's tip deflection and
        // rate; e^{−λ_k s} kept in dy until F_c is known
        let (mut w, mut wd) = (0.0, 0.0);
        let model = &fr.model;
        let node = self.anchor.node(s);
        for (k, l) in fr.modal.lambda.iter().enumerate() {
            // e^{λ_k s} and e^{−λ_k s}: tabulated at the step's nodes, else formed here
            let [er, ei, ir, ii] = match node {
                Some((row, _)) => [row[4 * k], row[4 * k + 1], row[4 * k + 2], row[4 * k + 3]],
                None => {
                    let mag = (l.re * s).exp();
                    let (sn, cs) = (l.im * s).sin_cos();
                    [mag * cs, mag * sn, cs / mag, -sn / mag]
                }
            };
            let (xr, xi) = (q0.re[k] + yr[k], q0.im[k] + yi[k]);
            let (qr, qi) = (er * xr - ei * xi, er * xi + ei * xr);
            w += tip.re[k] * qr - tip.im[k] * qi;
            wd += tip_dot.re[k] * qr - tip_dot.im[k] * qi;
            dr[k] = ir;
            di[k] = ii;
            fac[k] = [er, ei];
        }
        // sin, cos Ωτ: at a node by angle addition from the anchor's
        let sc = match node {
            Some((_, (sn, cs))) => {
                let (s0, c0) = self.anchor.trig;
                (s0 * cs + c0 * sn, c0 * cs - s0 * sn)
            }
            None => (model.omega() * t).sin_cos(),
        };
        // eq. 8 with z_p's tip part, then the law's force
        let (wt, wdt) = modal_tip(model.omega(), &fr.forced, (w, wd), sc);
        let [v, vd, _] = model.v_t_at(sc, [wt, wdt, 0.0]);
        let force = model.tip_sample().force(self.contact, -v, -vd);
        let f = force.force;
        if variational {
            // column j of Φ = X e^{Λs}(P + Y): its tip deflection and rate give the row
            // ∂F_c/∂z_a = −F_δ ∂W/∂z_a − F_δ̇ ∂Ẇ/∂z_a (δ = −V_T, ∂V_T/∂W = 1); then
            // Y′_kj = e^{−λ_k s} β_k (∂F_c/∂z_a)_j
            let p = &fr.modal.vinv_t;
            let (pr, pi) = (p.re.as_slice(), p.im.as_slice());
            let (yv, dv) = (&y[2 * r..], dvar);
            for (j, (col, out)) in yv
                .chunks_exact(2 * r)
                .zip(dv.chunks_exact_mut(2 * r))
                .enumerate()
            {
                let (cr, ci) = col.split_at(r);
                let (mut gw, mut gwd) = (0.0, 0.0);
                for k in 0..r {
                    let (xr, xi) = (pr[j * r + k] + cr[k], pi[j * r + k] + ci[k]);
                    let [er, ei] = fac[k];
                    let (qr, qi) = (er * xr - ei * xi, er * xi + ei * xr);
                    gw += tip.re[k] * qr - tip.im[k] * qi;
                    gwd += tip_dot.re[k] * qr - tip_dot.im[k] * qi;
                }
                let rho = -force.d_delta * gw - force.d_rate * gwd;
                let (or, oi) = out.split_at_mut(r);
                for k in 0..r {
                    let (br, bi) = (fr.beta.re[k] * rho, fr.beta.im[k] * rho);
                    or[k] = dr[k] * br - di[k] * bi;
                    oi[k] = dr[k] * bi + di[k] * br;
                }
            }
        }
        for k in 0..r {
            let (br, bi) = (fr.beta.re[k] * f, fr.beta.im[k] * f);
            let (er, ei) = (dr[k], di[k]);
            dr[k] = er * br - ei * bi;
            di[k] = er * bi + ei * br;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::ContactLaw;
    use crate::params::Params;

    /// The default DMT model with the sample one gap away (α5 = 1: V_T ≈ 1, so that F_c is
    /// well conditioned in the tip deflection and the comparisons below see the factors only).
    fn frame(modes: usize) -> LinearFrame {
        let p = Params {
            modes,
            alpha5: 1.0,
            contact_law: ContactLaw::Dmt {
                hamaker: 1e-5,
                intermolecular_distance: 0.01,
            },
            ..Params::default()
        };
        let m = CantileverModel::new(&p).unwrap();
        LinearFrame::new(&m).unwrap().unwrap()
    }

    /// The ladder's rung is the largest T·2^{−j/8} not above h.
    #[test]
    fn ladder_rungs_are_at_most_nine_percent_below_the_request() {
        let f = frame(1);
        let t = f.model.period();
        for k in 0..2000 {
            let h = t * 10f64.powf(-6.0 * k as f64 / 2000.0) * 0.999;
            let rung = f.ladder(h);
            assert!(
                rung <= h && rung >= h * (-1.0 / RUNGS).exp2(),
                "{h} → {rung}"
            );
            let j = (t / rung).log2() * RUNGS;
            assert!((j - j.round()).abs() < 1e-9, "{rung} is not a rung ({j})");
        }
    }

    /// A stage at a tabulated node gives the field of the direct factors (e^{λs} by exp and
    /// sin/cos, sin Ωτ directly) to round-off, and the state from y = 0 is z at the anchor.
    #[test]
    fn node_factors_equal_the_direct_ones() {
        let f = frame(3);
        let z: Vec<f64> = (0..6).map(|i| 0.1 * (i as f64 + 1.0).sin()).collect();
        let tau = 3.7;
        let mut a = f.anchor(tau, &z);
        let mut back = vec![0.0; 6];
        f.state_into(&a, tau, &vec![0.0; f.dim()], &mut back);
        for (x, y) in back.iter().zip(&z) {
            assert!((x - y).abs() < 1e-13, "{x} vs {y}");
        }
        let h = f.ladder(0.05);
        let y: Vec<f64> = (0..f.dim()).map(|i| 1e-3 * (i as f64).cos()).collect();
        for &c in &C[..16] {
            let t = tau + c * h;
            let (mut d0, mut d1) = (vec![0.0; f.dim()], vec![0.0; f.dim()]);
            a.table = None;
            f.field(Region::Free, &a).eval(t, &y, &mut d0);
            f.use_step(&mut a, h);
            assert!(a.node(t - tau).is_some());
            f.field(Region::Free, &a).eval(t, &y, &mut d1);
            // the node's s = c h and the stage's fl(τ + c h) − τ differ by an ulp of τ: a phase
            // error of at most 4ε(|τ| + |s|) max|λ_k| (τ shifted within its round-off)
            let scale = d0.iter().map(|x| x.abs()).fold(0.0, f64::max);
            let tol = 4.0 * f64::EPSILON * (tau + h) * f.modal.lambda_max + 1e-14;
            for (x, y) in d0.iter().zip(&d1) {
                assert!((x - y).abs() <= tol * scale, "c = {c}: {x} vs {y}");
            }
        }
    }
}

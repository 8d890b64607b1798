//! The last step and dense output: the homogeneous solution over the last step (energy or
//! modal coordinates), the state inside it, and its tip series — the Taylor expansion of V_T
//! that the switching search and the dense tip output share.

use super::forcing::Forced;
use super::modal::{ModalExp, Modes, MAXD};
use super::search::TipPoly;
use super::spectral::Spectral;
use super::tip::base_amp;
use super::{ExactPropagator, INV_FACT, INV_INT, K, TERM_BLOCKS};
use crate::linalg::matvec;
use crate::params::Params;
use crate::system::Region;
use nalgebra::DVector;

/// The homogeneous state a tip series is expanded from (`build_poly`): energy coordinates y,
/// or the modal coordinates q of y = V q.
#[derive(Clone, Copy)]
pub(super) enum SeriesStart<'a> {
    Energy(&'a [f64]),
    Modal(&'a ModalExp, &'a Modes),
}

/// Where `build_poly` expands a tip series: over the step [τ0, τ0 + `len`], centred at local
/// time `center` (with `trig` = (sin, cos) Ω(τ0 + center)), from the homogeneous state there
/// (`start`).
#[derive(Clone, Copy)]
pub(super) struct Expansion<'a> {
    pub(super) tau0: f64,
    pub(super) center: f64,
    pub(super) trig: (f64, f64),
    pub(super) len: f64,
    pub(super) start: SeriesStart<'a>,
}

/// The last step, kept for dense output.
#[derive(Debug, Clone)]
pub(super) struct LastStep {
    pub(super) tau0: f64,
    pub(super) region: Region,
    /// Homogeneous part δz(τ0) in plain coordinates (dense steps).
    pub(super) dz0: DVector<f64>,
    /// Modal coordinates of the homogeneous part at τ0 (modal steps; boxed, as the current
    /// coordinates and the scratch, so that a step's buffers trade places by pointer).
    pub(super) q0: Box<Modes>,
    /// Whether the step was modal.
    pub(super) modal: bool,
    /// Whether the step was a whole grid step (its transition matrix is Φ_s).
    pub(super) full: bool,
    /// Whether the last step is a span of several steps (`span.rs`): its tip series is built
    /// around the time asked for, and the next three fields hold its end.
    pub(super) span: bool,
    /// A span's modal coordinates at its end, in its region (q0 e^{Λt}).
    pub(super) q1: Box<Modes>,
    /// A span's (sin Ωτ, cos Ωτ) at its start and end.
    pub(super) trig0: (f64, f64),
    pub(super) trig1: (f64, f64),
    /// Sub-step index of the grid point a whole grid step started from.
    pub(super) k: usize,
}

impl ExactPropagator {
    /// out = e^{Ã t} y0 in energy coordinates: the eigendecomposition when available, else
    /// the Taylor series Σ Ãⁿ y0 tⁿ/n!.
    pub(super) fn hom_energy(sp: &Spectral, y0: &[f64], t: f64, out: &mut [f64]) {
        if let Some(me) = &sp.modal {
            return me.apply(y0, t, out);
        }
        let dim = y0.len();
        let mut term = [0.0; MAXD];
        let mut tmp = [0.0; MAXD];
        let (mut term, mut tmp) = (&mut term[..dim], &mut tmp[..dim]);
        out.copy_from_slice(y0);
        term.copy_from_slice(y0);
        let norm2 = |x: &[f64]| x.iter().map(|v| v * v).sum::<f64>();
        let floor = 1e-34 * norm2(y0);
        for n in 1..=K {
            matvec(&sp.at, term, tmp, t / n as f64, false);
            std::mem::swap(&mut term, &mut tmp);
            for (o, x) in out.iter_mut().zip(term.iter()) {
                *o += x;
            }
            if norm2(term) <= floor {
                break;
            }
        }
    }

    /// Homogeneous part at the start of the last step in energy coordinates.
    fn last_y0(&self, y0: &mut [f64]) {
        let sp = &self.spec[self.last.region.index()];
        match (&sp.modal, self.last.modal) {
            (Some(me), true) => ModalExp::expand(&me.v, &self.last.q0, y0, false),
            _ => matvec(&sp.t, self.last.dz0.as_slice(), y0, 1.0, false),
        }
    }

    /// State at local time t of the last step, in plain coordinates.
    pub(super) fn state_in_last(&self, t: f64, out: &mut [f64]) {
        let sc = (self.model.omega() * (self.last.tau0 + t)).sin_cos();
        self.state_in_last_at(t, sc, out);
    }

    /// [`Self::state_in_last`] given `sc` = (sin Ωτ, cos Ωτ) at τ = τ0 + t.
    pub(super) fn state_in_last_at(&self, t: f64, sc: (f64, f64), out: &mut [f64]) {
        let ri = self.last.region.index();
        let sp = &self.spec[ri];
        Self::zp_at(&self.forced[ri], sc, out);
        if let Some(me) = &sp.modal {
            // modal coordinates at τ0 (kept by a modal step, projected from δz by a dense one),
            // advanced by e^{Λt}
            if self.last.modal {
                return me.expand_advanced(&self.last.q0, t, out);
            }
            let mut q0 = Modes::ZERO;
            me.project_plain(self.last.dz0.as_slice(), &mut q0);
            return me.expand_advanced(&q0, t, out);
        }
        let dim = out.len();
        let (mut y0, mut yt) = ([0.0; MAXD], [0.0; MAXD]);
        self.last_y0(&mut y0[..dim]);
        Self::hom_energy(sp, &y0[..dim], t, &mut yt[..dim]);
        matvec(&sp.tinv, &yt[..dim], out, 1.0, true);
    }

    /// Fill `out` with the tip series of a step in region `r` expanded `at` the step
    /// [τ0, τ0 + len], centred at local time `center`, from the homogeneous state at
    /// τ0 + center (`start`: energy or modal coordinates). The series reaches |t − center| ≤
    /// max(center, len − center), half the step when centred, so its terms fall off twice as
    /// fast. The
    /// moments c̃ᵀÃⁿy (one product with the precomputed rows, or with the modal table of
    /// [`ModalExp::moments`]), then the Taylor coefficients of g and g′ four terms at a time
    /// (the harmonic factors Ωⁿ/n! from [`Forced`]) until the a priori tail bound is below
    /// round-off (1/n! and 1/n from tables: no division until it passes).
    pub(super) fn build_poly(
        sp: &Spectral,
        fr: &Forced,
        p: &Params,
        dead: f64,
        r: Region,
        at: &Expansion,
        out: &mut TipPoly,
    ) {
        let Expansion {
            tau0,
            center,
            trig: (s0, c0),
            len,
            start,
        } = *at;
        let radius = center.max(len - center);
        // the harmonic part a_s sin(Ωτc + Ωu) + a_c cos(Ωτc + Ωu) + const of V_T (τc = τ0 +
        // center, u = t − center): its n-th u-derivative at 0 is Ωⁿ (S, C, −S, −C)[n mod 4]
        let (a_s, a_c) = (fr.wp[1] + base_amp(p), fr.wp[2]);
        let (sv, sd) = (a_s * s0 + a_c * c0, a_s * c0 - a_c * s0);
        let (cycle, cyc1) = ([sv, sd, -sv, -sd], [sd, -sv, -sd, sv]);
        // the moments c̃ᵀÃⁿy and a bound |c̃ᵀÃⁿy| ≤ M ρⁿ (from energy coordinates,
        // ‖c̃‖‖y‖ ‖Ã‖₂ⁿ; from modal ones, Σ|w c̃ᵀv_k||q_k| max|λ_k|ⁿ)
        let mo = &mut out.mo;
        let (m_amp, rho) = match start {
            SeriesStart::Energy(y0) => {
                matvec(&sp.rows, y0, mo, 1.0, false);
                let y_norm = y0.iter().map(|v| v * v).sum::<f64>().sqrt();
                (sp.ct_norm * y_norm, sp.rho)
            }
            SeriesStart::Modal(me, q) => (me.moments(q, mo), me.lambda_max),
        };
        // a priori bound on the coefficients beyond n: |c̃ᵀÃ^{n+d}y| rⁿ/n! ≤ M ρ^{n+d} rⁿ/n!
        // and |harmonic| ≤ (|a_s| + |a_c|) Ω^{n+d} rⁿ/n! (d ≤ 2, r the radius), so with
        // x = max(ρ, Ω) r every size below is ≤ bound xⁿ/n! and the tail from n on
        // ≤ bound xⁿ/n! / (1 − x/(n+1)): the series stop as soon as that is below round-off of
        // the largest term so far
        let (om, amp) = (p.omega, a_s.abs() + a_c.abs());
        let bound = m_amp * (1.0 + rho + rho * rho) * 3.0 + amp * (1.0 + om + om * om) * 2.0;
        let wp_sum = fr.wp.iter().map(|x| x.abs()).sum::<f64>();
        let x = rho.max(om) * radius;
        let [hf0, hf1] = &fr.harm_fact;
        // in blocks of four terms (the harmonic cycle is the same in every block, and the lanes
        // of a block are independent): every term's coefficients, the size of its contribution
        // over the step (sums rather than maxima: a bound as good, without NaN-aware max
        // sequences) and its share of the bound on |g''|; then the block's terms in order until
        // the a priori tail is below round-off
        let mut size = [0.0; K + 1];
        let mut curv_n = [0.0; 4];
        let (mut biggest, mut x_pow, mut filled) = (0.0f64, x, K + 1);
        let mut curv = fr.vp_curv;
        let mut l = 1.0;
        'blocks: for j in 0..TERM_BLOCKS {
            // rⁿ of the block's terms
            let mut lp = [0.0; 4];
            for o in lp.iter_mut() {
                *o = l;
                l *= radius;
            }
            for i in 0..4 {
                let n = 4 * j + i;
                let f = INV_FACT[n];
                let (c0n, c1n, c2n) = (mo[n] * f, mo[n + 1] * f, mo[n + 2] * f);
                let g0 = c0n + hf0[n] * cycle[i];
                let g1 = c1n + hf1[n] * cyc1[i];
                out.gc[0][n] = g0;
                out.gc[1][n] = g1;
                curv_n[i] = c2n.abs() * lp[i];
                size[n] = (c0n.abs() + c1n.abs() + c2n.abs() + g0.abs() + g1.abs()) * lp[i];
            }
            for n in 4 * j..4 * j + 4 {
                if size[n] > biggest {
                    biggest = size[n];
                }
                curv += curv_n[n - 4 * j];
                // the tail from n + 1 on: bound xⁿ⁺¹/(n+1)! / (1 − x/(n+2))
                let x_fact = x_pow * INV_FACT[n + 1];
                let ratio = x * INV_INT[n + 2];
                x_pow *= x;
                if ratio < 0.5 && bound * x_fact <= 1e-18 * (biggest + wp_sum) * (1.0 - ratio) {
                    filled = n + 1;
                    curv += bound * x_fact / (1.0 - ratio);
                    break 'blocks;
                }
            }
        }
        out.gc[0][0] += fr.wp[0] + p.alpha5;
        let scale = biggest + wp_sum;
        let mut terms = filled;
        let mut tail = 0.0;
        while terms > 1 {
            tail += size[terms - 1];
            if tail > 1e-18 * scale {
                break;
            }
            terms -= 1;
        }
        out.tau0 = tau0;
        out.center = center;
        out.terms = terms;
        out.wp = fr.wp;
        out.omega = p.omega;
        out.trig_c = (s0, c0);
        out.cycle = cycle;
        out.sigma = r.guard_sign();
        out.dead = dead;
        out.curv = curv;
        out.refilled();
    }

    /// Build the tip series of the last step (unless the step built it), covering local time
    /// t (dense output). The series' own origin is `poly.tau0`: the last step's start, or for a
    /// span (`span.rs`), longer than the series converges over, the start of a window of one
    /// grid step centred at t, from the modal coordinates there (q0 e^{Λt}; kept while later
    /// times fall inside it).
    pub(super) fn poly_for_last(&mut self, t: f64) {
        if self.last.span {
            let at = self.last.tau0 + t;
            if !(self.poly_built && (0.0..=self.grid.h).contains(&(at - self.poly.tau0))) {
                self.build_last_series(t, SeriesAt::Window);
            }
            return;
        }
        if self.poly_built {
            return;
        }
        let step = self.tau - self.last.tau0;
        self.build_last_series(
            step.max(t),
            if t <= step {
                SeriesAt::Centred
            } else {
                SeriesAt::Start
            },
        );
    }

    /// Build the tip series of the last step: over local times [0, `t`] — for a whole modal
    /// grid step ([`SeriesAt::Centred`]) centred at its middle from the modal coordinates
    /// there (q0 e^{Λh/2}), so that it reaches half the step; otherwise from the step's start in
    /// energy coordinates — or over the grid step centred at local time `t` of a span
    /// ([`SeriesAt::Window`]). The switching search (`step_impl`) and dense output
    /// ([`Self::poly_for_last`]) use the same series of a step.
    pub(super) fn build_last_series(&mut self, t: f64, at: SeriesAt) {
        let ri = self.last.region.index();
        let dim = self.z.len();
        let h = self.grid.h;
        let mut y0 = [0.0; MAXD];
        let expansion = match (&self.spec[ri].modal, at) {
            (Some(me), SeriesAt::Window) => {
                let mid = &mut self.scratch;
                me.factors(t, mid);
                mid.mul_assign(&self.last.q0, me.len());
                let at = self.last.tau0 + t;
                Expansion {
                    tau0: at - 0.5 * h,
                    center: 0.5 * h,
                    trig: (self.model.omega() * at).sin_cos(),
                    len: h,
                    start: SeriesStart::Modal(me, &self.scratch),
                }
            }
            (Some(me), SeriesAt::Centred) if self.last.modal && self.last.full => {
                let mid = &mut self.scratch;
                mid.copy_prefix(&self.last.q0, me.len());
                mid.mul_assign(&self.forced[ri].half_fac, me.len());
                Expansion {
                    tau0: self.last.tau0,
                    center: 0.5 * t,
                    trig: self.trig_mid[self.last.k],
                    len: t,
                    start: SeriesStart::Modal(me, &self.scratch),
                }
            }
            _ => {
                self.last_y0(&mut y0[..dim]);
                let tau0 = self.last.tau0;
                Expansion {
                    tau0,
                    center: 0.0,
                    trig: self.trig_at(tau0),
                    len: t,
                    start: SeriesStart::Energy(&y0[..dim]),
                }
            }
        };
        Self::build_poly(
            &self.spec[ri],
            &self.forced[ri],
            self.model.params(),
            self.dead,
            self.last.region,
            &expansion,
            &mut self.poly,
        );
        self.poly_built = true;
    }
}

/// Where [`ExactPropagator::build_last_series`] expands the last step's tip series.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum SeriesAt {
    /// From the step's start.
    Start,
    /// At the middle of a whole modal grid step (else from the start).
    Centred,
    /// Over the grid step centred at a time inside a span.
    Window,
}

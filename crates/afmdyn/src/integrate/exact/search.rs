//! The tip motion inside one step as a power series, the certified parabola test and the
//! pruned leftmost-root search (see the parent module's docs).

use super::K;

/// The tip motion inside one step as a truncated power series plus the harmonic part.
#[derive(Debug, Clone)]
pub(super) struct TipPoly {
    pub(super) tau0: f64,
    /// The local time the series is expanded about: every sum is in u = t − center.
    pub(super) center: f64,
    /// The moments mo[n] = c̃ᵀÃⁿy, n = 0..=K + 2, of the homogeneous state y at the centre: the
    /// tip deflection W_hom and its first two derivatives have the Taylor coefficients
    /// mo[n + i] / n! (i = 0, 1, 2).
    pub(super) mo: [f64; K + 3],
    /// Taylor coefficients of V_T and dV_T/dτ in u = t − center: mo[n]/n!, mo[n+1]/n! plus those
    /// of the harmonic part W_p + α2 sin Ωτ + α5 (whose n-th derivative cycles through
    /// ±Ωⁿ(S, C)), so that the gap costs two Horner sums and no sine.
    pub(super) gc: [[f64; K + 1]; 2],
    /// Taylor coefficients of d²V_T/dτ², filled on first use by [`TipPoly::v_t`] (dense output
    /// only; the search does not need them).
    gc2: [f64; K + 1],
    /// Whether `gc2` belongs to this polynomial.
    gc2_ready: bool,
    /// Taylor coefficients mo[n + i]/n! of W_hom and its first two derivatives (i = 0, 1, 2),
    /// filled on first use by [`TipPoly::w`] (dense output only).
    hc: [[f64; K + 1]; 3],
    /// Whether `hc` belongs to this polynomial.
    hc_ready: bool,
    /// Terms kept: the tail beyond is below round-off over the step.
    pub(super) terms: usize,
    pub(super) wp: [f64; 3],
    pub(super) omega: f64,
    /// (sin Ωτ, cos Ωτ) at the centre, as the series was built with (from the grid's table at
    /// the middle of a whole grid step).
    pub(super) trig_c: (f64, f64),
    /// The harmonic part a_s sin Ωτ + a_c cos Ωτ of V_T (W_p plus the base drive) and its
    /// derivatives at the centre without their factors Ωⁿ: the n-th derivative is
    /// Ωⁿ cycle[n mod 4].
    pub(super) cycle: [f64; 4],
    pub(super) sigma: f64,
    /// Dead band added to the gap (see [`super::ExactPropagator`]'s `dead`).
    pub(super) dead: f64,
    /// Bound on |g''| over the step.
    pub(super) curv: f64,
}

impl TipPoly {
    /// A polynomial to be filled by the propagator (all zero).
    pub(super) fn empty() -> Self {
        TipPoly {
            tau0: 0.0,
            center: 0.0,
            mo: [0.0; K + 3],
            gc: [[0.0; K + 1]; 2],
            gc2: [0.0; K + 1],
            gc2_ready: false,
            hc: [[0.0; K + 1]; 3],
            hc_ready: false,
            terms: 1,
            wp: [0.0; 3],
            omega: 0.0,
            trig_c: (0.0, 1.0),
            cycle: [0.0; 4],
            sigma: 1.0,
            dead: 0.0,
            curv: 0.0,
        }
    }
    /// Σ cₙ tⁿ as Σ_{i<4} tⁱ Pᵢ(t⁴), the coefficients n ≡ i (mod 4) in four independent
    /// Horner chains (the k-th order Horner scheme, Knuth, *TAOCP* vol. 2, §4.6.4): a quarter of
    /// the latency of one chain over all the terms, which bounds the search's evaluations.
    #[inline]
    fn horner(c: &[f64], t: f64) -> f64 {
        let t2 = t * t;
        let t4 = t2 * t2;
        let (quads, rest) = c.as_chunks::<4>();
        // the top (len mod 4) coefficients start the chains
        let mut p = [0.0; 4];
        p[..rest.len()].copy_from_slice(rest);
        for q in quads.iter().rev() {
            for (pi, &ci) in p.iter_mut().zip(q) {
                *pi = *pi * t4 + ci;
            }
        }
        (p[0] + t * p[1]) + t2 * (p[2] + t * p[3])
    }
    /// The coefficients derived on first use (`gc2`, `hc`) no longer belong to the series: the
    /// propagator's `build_poly` has filled it anew.
    pub(super) fn refilled(&mut self) {
        self.gc2_ready = false;
        self.hc_ready = false;
    }
    /// [W, W', W''] of the tip at local time t: Σ mo[n + i] uⁿ/n! over the kept terms (the
    /// i-th derivative of W_hom, its coefficients formed on the first call) plus the harmonic
    /// part W_p, its sine and cosine turned from the centre's by Ωu (the angle-addition
    /// formulas): the phase is that of the series' V_T and of the grid steps, whatever the
    /// size of τ, where sin Ωτ of a large τ would carry the rounding of Ωτ (about τ ulp).
    pub(super) fn w(&mut self, t: f64) -> [f64; 3] {
        if !self.hc_ready {
            for (i, hc) in self.hc.iter_mut().enumerate() {
                for (n, o) in hc[..self.terms].iter_mut().enumerate() {
                    *o = self.mo[n + i] * super::INV_FACT[n];
                }
            }
            self.hc_ready = true;
        }
        let u = t - self.center;
        let (su, cu) = (self.omega * u).sin_cos();
        let (sc, cc) = self.trig_c;
        let (s, c) = (sc * cu + cc * su, cc * cu - sc * su);
        let (w0, ws, wc) = (self.wp[0], self.wp[1], self.wp[2]);
        let om = self.omega;
        let hom = |i: usize| Self::horner(&self.hc[i][..self.terms], u);
        [
            hom(0) + w0 + ws * s + wc * c,
            hom(1) + om * (ws * c - wc * s),
            hom(2) - om * om * (ws * s + wc * c),
        ]
    }
    /// [V_T, dV_T/dτ, d²V_T/dτ²] at local time t: three Horner sums, no sine (the harmonic
    /// part is in the coefficients; those of V_T'' are formed on the first call, as `gc` by the
    /// propagator's `build_poly`: mo[n + 2]/n! plus the n-th derivative Ωⁿ⁺² `cycle`[(n+2) mod 4]
    /// of the harmonic part at the centre, over n!).
    pub(super) fn v_t(&mut self, t: f64) -> [f64; 3] {
        if !self.gc2_ready {
            let mut om_n = self.omega * self.omega;
            for n in 0..self.terms {
                let f = super::INV_FACT[n];
                self.gc2[n] = self.mo[n + 2] * f + om_n * self.cycle[(n + 2) % 4] * f;
                om_n *= self.omega;
            }
            self.gc2_ready = true;
        }
        let u = t - self.center;
        [
            Self::horner(&self.gc[0][..self.terms], u),
            Self::horner(&self.gc[1][..self.terms], u),
            Self::horner(&self.gc2[..self.terms], u),
        ]
    }
    /// Gap g = σ V_T and its derivative at local time t.
    pub(super) fn g(&self, t: f64) -> (f64, f64) {
        let u = t - self.center;
        let v = Self::horner(&self.gc[0][..self.terms], u);
        let dv = Self::horner(&self.gc[1][..self.terms], u);
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

/// True when the curvature bound b ≥ |g''| proves g > 0 on the open interval (0, len): first
/// the cheap sufficient bound g(s) ≥ g(0) + g′(0) s − b s²/2 ≥ g(0) + min(g′(0), 0) len −
/// b len²/2 for every s in the interval (no square root or division, and no dependence on the
/// end: most steps away from the sample pass it), then the two parabolas from both ends.
pub(super) fn certified_positive(ga: f64, da: f64, gb: f64, db: f64, b: f64, len: f64) -> bool {
    let low = ga + da.min(0.0) * len - 0.5 * b * len * len;
    low > 0.0 || (gb > 0.0 && parabola_root(ga, da, b) + parabola_root(gb, -db, b) > len)
}

/// The gap g = σ V_T + dead and its rate g′ = σ dV_T/dτ at the start (`ga`, `da`) and the end
/// (`gb`, `db`) of a step, from (V_T, dV_T/dτ) at both ends and the guard sign σ of the region.
#[derive(Debug, Clone, Copy)]
pub(super) struct StepEnds {
    pub(super) ga: f64,
    pub(super) da: f64,
    pub(super) gb: f64,
    pub(super) db: f64,
    /// The step starts at a switching (`just_switched`), or on the sample within the dead band
    /// (g(a) ≤ 0); g(a) is then taken as 0.
    pub(super) switched: bool,
}

impl StepEnds {
    pub(super) fn new(
        sigma: f64,
        dead: f64,
        (va, vda): (f64, f64),
        (vb, vdb): (f64, f64),
        just_switched: bool,
    ) -> StepEnds {
        let mut ga = sigma * va + dead;
        let switched = just_switched || ga <= 0.0;
        if switched {
            ga = ga.max(0.0);
        }
        StepEnds {
            ga,
            da: sigma * vda,
            gb: sigma * vb + dead,
            db: sigma * vdb,
            switched,
        }
    }

    /// [`certified_positive`] over a step of `len` with curvature bound `curv`.
    pub(super) fn certified(&self, curv: f64, len: f64) -> bool {
        certified_positive(self.ga, self.da, self.gb, self.db, curv, len)
    }
}

pub(super) struct Search<'a> {
    pub(super) poly: &'a TipPoly,
}

impl Search<'_> {
    /// Leftmost t in (a, b] with g(t) ≤ 0, given g(a) > 0; None when g > 0 on (a, b].
    pub(super) fn first(
        &self,
        a: f64,
        ga: (f64, f64),
        b: f64,
        gb: (f64, f64),
        depth: u32,
    ) -> Option<f64> {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The certified test is sound: for cubics g(s) = g0 + d0 s + c2 s²/2 + c3 s³/6 with the
    /// curvature bound B = |c2| + |c3| len ≥ |g''| on [0, len], whenever it proves g > 0 the
    /// cubic is positive at 2001 points of the interval; it proves it for steps far from zero
    /// (through the cheap bound alone) and never for a cubic that vanishes inside.
    #[test]
    fn certified_positive_is_sound() {
        let len = 0.7;
        let (mut proven, mut cheap, mut cases) = (0, 0, 0);
        let vals = [-2.0, -0.6, -0.05, 0.0, 0.05, 0.6, 2.0];
        for g0 in [1e-3, 0.02, 0.1, 0.5, 3.0] {
            for d0 in vals {
                for c2 in vals {
                    for c3 in vals {
                        let g = |s: f64| g0 + d0 * s + c2 * s * s / 2.0 + c3 * s * s * s / 6.0;
                        let dg = |s: f64| d0 + c2 * s + c3 * s * s / 2.0;
                        let b = c2.abs() + c3.abs() * len;
                        cases += 1;
                        if !certified_positive(g0, d0, g(len), dg(len), b, len) {
                            continue;
                        }
                        proven += 1;
                        if g0 + d0.min(0.0) * len - 0.5 * b * len * len > 0.0 {
                            cheap += 1;
                        }
                        let min = (0..=2000)
                            .map(|i| g(len * i as f64 / 2000.0))
                            .fold(f64::INFINITY, f64::min);
                        assert!(min > 0.0, "g0 {g0} d0 {d0} c2 {c2} c3 {c3}: min {min}");
                    }
                }
            }
        }
        assert!(
            cheap > cases / 10 && proven > cheap,
            "{cheap} {proven} {cases}"
        );
        // a root inside: never proven
        let g = |s: f64| 0.1 - s + s * s;
        assert!(!certified_positive(g(0.0), -1.0, g(1.0), 1.0, 2.0, 1.0));
    }
}

//! `jkr` — Johnson, Kendall & Roberts, *Proc. R. Soc. Lond. A* 324 (1971) 301: a compliant,
//! adhesive sphere–flat contact with a neck. No force outside contact. In contact the contact
//! radius a sets both the force and the indentation (Johnson, *Contact Mechanics*, CUP 1985,
//! §5.5): F = 4E*a³/(3R) − √(8πWE*a³), δ = a²/R − √(2πWa/E*). With h = a²/R (the Hertz
//! indentation of that radius), q = h^{1/4}, the Hertz group α4 = (4/3)E*√(R g₀) L³/(EI) and
//! the adhesion group P̃ = πWR/F̃-unit this is, exactly,
//! F_c = α4 q⁶ − √(6P̃α4) q³ + α6 q² δ̇,  δ = q⁴ − c q,  c = √(8P̃/(3α4)),
//! the damper α6 q² δ̇ = α6 √h δ̇ being Kelvin–Voigt's ∝ the contact radius a = √(Rh), as
//! DMT's. The contact forms at δ = 0 on approach (the force jumps to −(4/3)P̃, a₀³ = 2πWR²/E*),
//! and breaks on retraction where the branch ends, dδ/da = 0: δ_f = −3 q_f⁴, q_f³ = c/4
//! (−(3/4)(π²W²R/E*²)^{1/3} in SI, the pull-off under fixed grips, force −(5/6)P̃). The
//! load-controlled pull-off, min F = −(3/2)P̃ = −(3/2)πWR, lies on the branch. Each tap loses
//! the hysteresis E_hys = ∫_{δ_f}^0 |F| dδ = (3/5 + 4^{−1/3}/10) P̃ c^{4/3}
//! = (3/5 + 4^{−1/3}/10) 2^{2/3} π^{5/3} (W⁵R⁴/E*²)^{1/3} ≈ 7.09 (W⁵R⁴/E*²)^{1/3} (from
//! the potential below). The region is hysteretic: contact persists while δ > δ_f.

use super::{ForceEval, Hysteresis, Law, Param, PreparedForce, SampleSi};
use crate::error::ParamError;

/// Default JKR adhesion group P̃ = πWR = 0.05: the work of adhesion of DMT's defaults (whose
/// pull-off 2πRW is H̃/ã₀² = 0.1), so the JKR pull-off (3/2)P̃ = 0.075 is ¾ of DMT's, as the
/// two theories give for one W.
pub const JKR_DEFAULT_ADHESION: f64 = 0.05;

/// The JKR law's group.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JkrLaw {
    /// P̃ = πWR/F̃-unit > 0 (W the work of adhesion): the load-controlled pull-off force is
    /// (3/2)P̃.
    pub adhesion: f64,
}

impl Law for JkrLaw {
    const TIP_RADIUS: bool = true;
    const DOC: &'static str = "JKR: adhesive Hertz contact with a neck, formed at δ = 0, broken at δ_f < 0 (Johnson, Kendall & Roberts 1971)";
    const SAMPLE_KEYS: &'static [&'static str] = &["law", "youngs_modulus", "poisson_ratio", "hamaker", "intermolecular_distance", "viscosity", "z_c", "adhesion_energy"];
    const PARAMS: &'static [Param] = &[Param {
        name: "adhesion",
        symbol: "P̃",
        unit: "1",
        range: "0 < P̃ ≤ 1e12",
        default: JKR_DEFAULT_ADHESION,
        doc: "adhesion group P̃ = πWR/F (W the work of adhesion): pull-off (3/2)P̃",
        si_keys: &["adhesion_energy", "radius"],
        under_probe: Some("give the work of adhesion in the probe file's [sample] adhesion_energy (J/m², law = \"jkr\")"),
    }];

    type Prepared = PreparedJkr;

    fn validate(&self) -> Result<(), ParamError> {
        let adhesion = self.adhesion;
        // P̃ = 0 is Hertz (use `hertz`); the neck's scale P̃/α4 must stay resolvable
        if !(adhesion.is_finite() && adhesion > 0.0 && adhesion <= 1e12) {
            return Err(ParamError::Law {
                name: "adhesion (JKR group P̃ = πWR)",
                value: adhesion,
                range: "0 < P̃ ≤ 1e12",
            });
        }
        Ok(())
    }
    fn validate_shared(&self, alpha4: f64, _c: f64) -> Result<(), ParamError> {
        // the JKR branch scales with P̃/α4 (δ_f = −3(P̃/(6α4))^{2/3}): α4 = 0 has no
        // elastic contact, and beyond 1e12 the neck is below resolution or the whole gap
        let ratio = self.adhesion / alpha4;
        if !(alpha4 > 0.0 && (1e-12..=1e12).contains(&ratio)) {
            return Err(ParamError::Law {
                name: "alpha4 (contact stiffness α4, the JKR Hertz group)",
                value: alpha4,
                range: "α4 > 0 with 1e-12 ≤ P̃/α4 ≤ 1e12 (the neck's scale)",
            });
        }
        Ok(())
    }
    fn from_si(si: &SampleSi) -> Result<(Self, f64, f64), String> {
        // P̃ = πWR/F_s; the Kelvin–Voigt term η a δ̇ = η √(Rh) δ̇ as DMT's
        let rr = si.radius.unwrap_or(0.0);
        let law = JkrLaw {
            adhesion: std::f64::consts::PI * si.adhesion_energy.unwrap_or(0.0) * rr / si.force,
        };
        Ok((law, si.hertz_alpha4(), si.kelvin_voigt_alpha6()))
    }
    fn prepare(&self, k: f64, c: f64) -> PreparedJkr {
        PreparedJkr {
            jkr: Jkr::new(k, self.adhesion),
            damping: c,
        }
    }
    fn force(&self, k: f64, c: f64, contact: bool, delta: f64, rate: f64) -> ForceEval {
        self.prepare(k, c).force(contact, delta, rate)
    }
    fn potential(&self, k: f64, contact: bool, delta: f64) -> f64 {
        self.prepare(k, 0.0).potential(contact, delta)
    }
    fn dissipative(&self, k: f64, c: f64, delta: f64, rate: f64) -> f64 {
        self.prepare(k, c).dissipative(delta, rate)
    }
    fn hysteresis(&self, alpha4: f64) -> Option<Hysteresis> {
        let jkr = Jkr::new(alpha4, self.adhesion);
        Some(Hysteresis {
            release_distance: -jkr.release(),
            // the load-controlled pull-off, min F = −(3/2)P̃, on the branch
            pull_off_force: 1.5 * self.adhesion,
            energy_per_tap: jkr.hysteresis(),
        })
    }
}

/// JKR's prepare step (`Law::prepare`): the contact's constants (`Jkr::new`: two square
/// roots and a cube root of α4 and P̃) with the Kelvin–Voigt group α6. No force outside
/// contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PreparedJkr {
    /// The contact's constants.
    pub jkr: Jkr,
    /// α6.
    pub damping: f64,
}

impl PreparedForce for PreparedJkr {
    fn force(&self, contact: bool, delta: f64, rate: f64) -> ForceEval {
        if !contact {
            return ForceEval::default();
        }
        self.jkr.contact_force(self.damping, delta, rate)
    }
    fn potential(&self, contact: bool, delta: f64) -> f64 {
        if !contact {
            return 0.0;
        }
        self.jkr.contact_potential(delta)
    }
    fn dissipative(&self, delta: f64, rate: f64) -> f64 {
        self.jkr.dissipative(self.damping, delta, rate)
    }
}

/// The JKR contact in the law's units (module docs): Hertz group α4, adhesion P̃ = πWR, and
/// the contact-radius variable q = h^{1/4} = (a²/R)^{1/4} on the stable branch q ≥ q_f.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jkr {
    /// α4.
    pub alpha4: f64,
    /// P̃.
    pub adhesion: f64,
    /// c = √(8P̃/(3α4)): δ = q⁴ − c q.
    pub c: f64,
    /// b = √(6P̃α4): F = α4 q⁶ − b q³.
    pub b: f64,
    /// q_f = (c/4)^{1/3}: the end of the branch (dδ/dq = 0).
    pub q_end: f64,
    /// q_b = (1 + [`JKR_BREAK_CUT`]) q_f, where the contact breaks, just before the end of the
    /// branch.
    pub q_break: f64,
}

/// The JKR branch is cut just before its end: the contact breaks at q_b = (1 + 1e-3) q_f,
/// δ_b = δ_f (1 − 2.0e-6). At the end dF/dδ ∝ 1/√(δ − δ_f) is unbounded, and the variational
/// equations (orbits, multipliers, shooting) stall on it (steps of 1e-17 measured); at the cut
/// it is finite (1/(4q_b³ − c) = 1/(3.0e-3 c)). The break force is (5/6)P̃(1 + 2.4e-3) and
/// E_hys is 1.2e-6 lower, relatively (`Jkr::hysteresis` is that of the cut branch,
/// [`Jkr::hysteresis_uncut`] the closed form).
pub const JKR_BREAK_CUT: f64 = 1e-3;

impl Jkr {
    /// The contact of Hertz group `alpha4` > 0 and adhesion `adhesion` = P̃ > 0.
    pub(crate) fn new(alpha4: f64, adhesion: f64) -> Jkr {
        let c = (8.0 * adhesion / (3.0 * alpha4)).sqrt();
        let q_end = (0.25 * c).cbrt();
        Jkr {
            alpha4,
            adhesion,
            c,
            b: (6.0 * adhesion * alpha4).sqrt(),
            q_end,
            q_break: (1.0 + JKR_BREAK_CUT) * q_end,
        }
    }

    /// F_c(δ, δ̇) in contact with its partials, α6 = `c` the Kelvin–Voigt group (module docs):
    /// F_c = α4 q⁶ − b q³ + α6 q² δ̇ at q = q(δ) (`Jkr::radius_variable`). The force of
    /// [`JkrLaw`]'s `Law::force` in contact, from constants computed once
    /// ([`PreparedJkr`]).
    pub(crate) fn contact_force(&self, c: f64, delta: f64, rate: f64) -> ForceEval {
        let q = self.radius_variable(delta);
        let (f, df_dq) = self.elastic(q);
        let q2 = q * q;
        // dq/dδ = 1/(4q³ − c), large but finite at the break q_b ([`JKR_BREAK_CUT`]);
        // beyond it, where an integrator's stage may look across the guard, q stays at
        // q_b and the force at its break value
        let dq = if delta > self.release() {
            1.0 / (4.0 * q2 * q - self.c)
        } else {
            0.0
        };
        ForceEval {
            force: f + c * q2 * rate,
            d_delta: (df_dq + 2.0 * c * q * rate) * dq,
            d_rate: c * q2,
        }
    }

    /// The potential U(δ) in contact: [`Jkr::potential`] at q(δ).
    pub(crate) fn contact_potential(&self, delta: f64) -> f64 {
        self.potential(self.radius_variable(delta))
    }

    /// The dissipative part α6 q² δ̇ of the force at δ, α6 = `c`.
    pub fn dissipative(&self, c: f64, delta: f64, rate: f64) -> f64 {
        let q = self.radius_variable(delta);
        c * q * q * rate
    }

    /// δ(q) = q⁴ − c q.
    pub(crate) fn indentation(&self, q: f64) -> f64 {
        let q2 = q * q;
        q2 * q2 - self.c * q
    }

    /// The indentation where the contact breaks, δ_b = δ(q_b) < 0 ([`JKR_BREAK_CUT`]), with
    /// δ_f = −3q_f⁴ the end of the branch (the fixed-grips pull-off, −(3/4)(π²W²R/E*²)^{1/3}
    /// in SI).
    pub(crate) fn release(&self) -> f64 {
        self.indentation(self.q_break)
    }

    /// q = c^{1/3} where the contact forms on approach (δ = 0).
    pub(crate) fn q_contact(&self) -> f64 {
        self.c.cbrt()
    }

    /// The elastic–adhesive force F(q) = α4 q⁶ − b q³ and dF/dq.
    pub(crate) fn elastic(&self, q: f64) -> (f64, f64) {
        let q3 = q * q * q;
        (
            self.alpha4 * q3 * q3 - self.b * q3,
            6.0 * self.alpha4 * q3 * q * q - 3.0 * self.b * q * q,
        )
    }

    /// U(q) = ∫_{δ_b}^{δ(q)} F dδ = G(q) − G(q_b), with
    /// G(q) = (2/5)α4 q¹⁰ − ((α4c + 4b)/7) q⁷ + (bc/4) q⁴ the integral of
    /// F(q) δ′(q) = (α4q⁶ − bq³)(4q³ − c): 0 at the break, so the potential is continuous there
    /// and drops by E_hys = −U(q_contact) where the contact forms.
    pub fn potential(&self, q: f64) -> f64 {
        let g = |q: f64| {
            let q2 = q * q;
            let q4 = q2 * q2;
            let q7 = q4 * q2 * q;
            0.4 * self.alpha4 * q7 * q2 * q - (self.alpha4 * self.c + 4.0 * self.b) / 7.0 * q7
                + 0.25 * self.b * self.c * q4
        };
        g(q) - g(self.q_break)
    }

    /// The energy lost per contact cycle (formed at δ = 0, broken at δ_b) by the
    /// elastic–adhesive force alone: E_hys = −U(q_contact).
    pub(crate) fn hysteresis(&self) -> f64 {
        -self.potential(self.q_contact())
    }

    /// The closed form of the uncut branch (broken at δ_f): E_hys = (3/5 + 4^{−1/3}/10) P̃
    /// c^{4/3} (module docs), 1.2e-6 above `Jkr::hysteresis` relatively.
    pub fn hysteresis_uncut(&self) -> f64 {
        (0.6 + 0.1 / 4f64.cbrt()) * self.adhesion * self.c.powf(4.0 / 3.0)
    }

    /// q(δ) on the stable branch: the root q ≥ q_f of q⁴ − c q = δ (q_b for δ ≤ δ_b: beyond
    /// the break, where an integrator's stage may look across the guard). Newton's
    /// iteration on the convex, increasing δ(q) from a start right of the root converges
    /// monotonically; the start is the smaller of two upper bounds, max((2δ)^{1/4}, (2c)^{1/3})
    /// (where q⁴/2 bounds both δ and c q) and q_f + √((δ − δ_f)/(6q_f²)) (δ(q) − δ_f ≥
    /// 6q_f²(q − q_f)²), the second exact to leading order at the break, where δ′(q_f) = 0.
    pub(crate) fn radius_variable(&self, delta: f64) -> f64 {
        if delta.is_nan() || delta <= self.indentation(self.q_break) {
            return self.q_break;
        }
        let qf = self.q_end;
        let above = delta - self.indentation(qf);
        // (2c)^{1/3} = 2 q_f, since q_f³ = c/4
        let far = (2.0 * delta.max(0.0)).sqrt().sqrt().max(2.0 * qf);
        let near = qf + (above / (6.0 * qf * qf)).sqrt();
        let mut q = far.min(near).max(qf);
        for _ in 0..100 {
            let q2 = q * q;
            let f = q2 * q2 - self.c * q - delta;
            let d = 4.0 * q2 * q - self.c;
            if !(f > 0.0 && d > 0.0) {
                break;
            }
            let next = q - f / d;
            if next.is_nan() || next >= q || next <= qf {
                q = next.max(qf);
                break;
            }
            q = next;
        }
        q
    }
}

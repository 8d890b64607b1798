//! A tip–sample law with the constants it derives from its groups computed once, where the
//! model is built: what the integrators and the observables evaluate millions of times.

use super::{ContactLaw, ForceEval, Jkr, TipSample, TipSampleLaw};

/// A [`TipSample`] with its law's derived constants prepared once: JKR's c, b, q_f, q_b (two
/// square roots and a cube root of α4 and P̃, [`Jkr::new`]) instead of at every force
/// evaluation. Every evaluation is the law's own ([`TipSampleLaw`] of [`TipSample`]) with the
/// same operations in the same order, so the same numbers bit for bit; the other laws derive
/// nothing worth keeping (their constants are products of the groups, or a division outside
/// the hot path).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PreparedLaw {
    ts: TipSample,
    /// JKR's constants ([`Jkr::new`] of α4 and P̃); `None` for the other laws.
    jkr: Option<Jkr>,
}

impl PreparedLaw {
    /// Prepare `ts`'s law with its α4 and α6.
    pub fn new(ts: TipSample) -> PreparedLaw {
        let jkr = match ts.law {
            ContactLaw::Jkr { adhesion } => Some(Jkr::new(ts.stiffness, adhesion)),
            _ => None,
        };
        PreparedLaw { ts, jkr }
    }

    /// The law with its α4 and α6.
    pub fn tip_sample(&self) -> &TipSample {
        &self.ts
    }

    /// The law.
    pub fn law(&self) -> &ContactLaw {
        &self.ts.law
    }

    /// α6: the damper of the linear and Hertz laws, the Kelvin–Voigt group of the others.
    pub fn damping(&self) -> f64 {
        self.ts.damping
    }
}

impl TipSampleLaw for PreparedLaw {
    fn force(&self, contact: bool, delta: f64, rate: f64) -> ForceEval {
        match &self.jkr {
            Some(_) if !contact => ForceEval::default(),
            Some(jkr) => jkr.contact_force(self.ts.damping, delta, rate),
            None => self.ts.force(contact, delta, rate),
        }
    }

    fn potential(&self, contact: bool, delta: f64) -> f64 {
        match &self.jkr {
            Some(_) if !contact => 0.0,
            Some(jkr) => jkr.contact_potential(delta),
            None => self.ts.potential(contact, delta),
        }
    }

    fn dissipative(&self, contact: bool, delta: f64, rate: f64) -> f64 {
        match &self.jkr {
            Some(_) if !contact => 0.0,
            Some(jkr) => jkr.dissipative(self.ts.damping, delta, rate),
            None => self.ts.dissipative(contact, delta, rate),
        }
    }

    fn acts_outside(&self) -> bool {
        self.ts.acts_outside()
    }
}

//! A tip–sample law with the constants it derives from its groups computed once, where the
//! model is built: what the integrators and the observables evaluate millions of times. Each
//! law's module does its own prepare step ([`Law::prepare`]); the registry's
//! [`PreparedContact`] holds the result of whichever law the model has.

use super::{ContactLaw, ForceEval, Law, PreparedContact, TipSample, TipSampleLaw};

/// A law's force with its constants prepared ([`Law::Prepared`]): the evaluations of
/// [`TipSampleLaw`] without the region's bookkeeping.
pub trait PreparedForce {
    /// F_c(δ, δ̇) with its partials ([`Law::force`]); `contact` is the region.
    fn force(&self, contact: bool, delta: f64, rate: f64) -> ForceEval;
    /// The potential U(δ) of the conservative part ([`Law::potential`]).
    fn potential(&self, contact: bool, delta: f64) -> f64;
    /// The dissipative part F_d of F_c in contact ([`Law::dissipative`]).
    fn dissipative(&self, delta: f64, rate: f64) -> f64;
}

/// The prepare step of a law that derives nothing worth keeping (its constants are products of
/// the groups, or a division outside the hot path): the law with its α4 and α6, evaluated by
/// its own [`Law`] methods.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AsGiven<L> {
    /// The law's groups.
    pub law: L,
    /// α4.
    pub k: f64,
    /// α6.
    pub c: f64,
}

impl<L: Law> PreparedForce for AsGiven<L> {
    fn force(&self, contact: bool, delta: f64, rate: f64) -> ForceEval {
        self.law.force(self.k, self.c, contact, delta, rate)
    }

    fn potential(&self, contact: bool, delta: f64) -> f64 {
        self.law.potential(self.k, contact, delta)
    }

    fn dissipative(&self, delta: f64, rate: f64) -> f64 {
        self.law.dissipative(self.k, self.c, delta, rate)
    }
}

/// [`Law::Prepared`] and [`Law::prepare`] of a law that derives nothing worth keeping
/// ([`AsGiven`]).
macro_rules! as_given {
    () => {
        type Prepared = $crate::contact::AsGiven<Self>;
        fn prepare(&self, k: f64, c: f64) -> Self::Prepared {
            $crate::contact::AsGiven { law: *self, k, c }
        }
    };
}
pub(crate) use as_given;

/// A [`TipSample`] with its law's derived constants prepared once ([`ContactLaw::prepare`]:
/// each law's own [`Law::prepare`], e.g. JKR's c, b, q_f, q_b — two square roots and a cube
/// root of α4 and P̃, `super::Jkr::new` — and DMT's adhesion −H̃/ã₀²) instead of at every
/// force evaluation. Every evaluation is the law's own ([`TipSampleLaw`] of [`TipSample`]) with
/// the same operations in the same order, so the same numbers bit for bit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PreparedLaw {
    ts: TipSample,
    /// The law's constants ([`ContactLaw::prepare`] of α4 and α6).
    prepared: PreparedContact,
}

impl PreparedLaw {
    /// Prepare `ts`'s law with its α4 and α6.
    pub(crate) fn new(ts: TipSample) -> PreparedLaw {
        PreparedLaw {
            ts,
            prepared: ts.law.prepare(ts.stiffness, ts.damping),
        }
    }

    /// The law with its α4 and α6.
    #[cfg(test)]
    pub(crate) fn tip_sample(&self) -> &TipSample {
        &self.ts
    }

    /// The law.
    pub(crate) fn law(&self) -> &ContactLaw {
        &self.ts.law
    }

    /// α6: the damper of the linear and Hertz laws, the Kelvin–Voigt group of the others.
    pub(crate) fn damping(&self) -> f64 {
        self.ts.damping
    }
}

impl TipSampleLaw for PreparedLaw {
    fn force(&self, contact: bool, delta: f64, rate: f64) -> ForceEval {
        self.prepared.force(contact, delta, rate)
    }

    fn potential(&self, contact: bool, delta: f64) -> f64 {
        self.prepared.potential(contact, delta)
    }

    fn dissipative(&self, contact: bool, delta: f64, rate: f64) -> f64 {
        if !contact {
            return 0.0;
        }
        self.prepared.dissipative(delta, rate)
    }

    fn acts_outside(&self) -> bool {
        self.ts.acts_outside()
    }
}

//! Pieces shared by the integrators' implementations: the chattering test, the step budget of
//! the integrators that choose their own steps, and the Hermite dense output of the
//! Runge–Kutta ones.

use crate::error::SimError;
use crate::system::Region;
use crate::tip_sample::TipSampleSystem;
use nalgebra::DVector;

/// The chattering test of an integrator: `count` events within `window` of the latest one are
/// reported as [`SimError::Chattering`] (an accumulation of switchings or impacts that the event
/// loop would otherwise follow forever).
#[derive(Debug, Clone)]
pub(crate) struct ChatterWindow {
    count: usize,
    window: f64,
    recent: std::collections::VecDeque<f64>,
}

impl ChatterWindow {
    /// `count` events within a time `window`.
    pub(crate) fn new(count: usize, window: f64) -> Self {
        ChatterWindow {
            count,
            window,
            recent: std::collections::VecDeque::with_capacity(count + 1),
        }
    }

    /// Record an event at `tau`.
    ///
    /// # Errors
    /// [`SimError::Chattering`] when it is the `count`-th within the window.
    pub(crate) fn record(&mut self, tau: f64) -> Result<(), SimError> {
        // an event earlier than the last one belongs to a new run (a restart back in time):
        // the window counts the events of one run only
        if self.recent.back().is_some_and(|&t| tau < t) {
            self.recent.clear();
        }
        self.recent.push_back(tau);
        while self.recent.len() > self.count {
            self.recent.pop_front();
        }
        if self.recent.len() == self.count {
            let window = tau - self.recent[0];
            if window < self.window {
                return Err(SimError::Chattering {
                    tau,
                    count: self.count,
                    window,
                });
            }
        }
        Ok(())
    }

    /// Forget the recorded events (a new start).
    pub(crate) fn clear(&mut self) {
        self.recent.clear();
    }
}

/// The steps of an integrator that chooses its own steps (adaptive DOP853, Taylor): the work
/// since construction ([`Integrator::work`]) and the budget of one drive period
/// ([`crate::params::ADAPTIVE_STEPS_PER_PERIOD`] steps within ⌊τ/T⌋, accepted and rejected).
/// Interior mutability, so that the `&self` step loops can count.
#[derive(Debug, Clone)]
pub(crate) struct StepBudget {
    what: &'static str,
    period: f64,
    /// The drive period counted and the steps taken in it.
    current: std::cell::Cell<(i64, usize)>,
    work: std::cell::Cell<u64>,
}

impl StepBudget {
    /// A budget of the integrator named `what` (in its error) over drive periods of `period`.
    pub(crate) fn new(what: &'static str, period: f64) -> Self {
        StepBudget {
            what,
            period,
            current: std::cell::Cell::new((i64::MIN, 0)),
            work: std::cell::Cell::new(0),
        }
    }

    /// Count one step taken at `tau`.
    ///
    /// # Errors
    /// [`SimError::Budget`] beyond [`crate::params::ADAPTIVE_STEPS_PER_PERIOD`] steps in one
    /// drive period.
    pub(crate) fn count(&self, tau: f64) -> Result<(), SimError> {
        let k = (tau / self.period).floor() as i64;
        self.work.set(self.work.get() + 1);
        let (at, n) = self.current.get();
        let n = if at == k { n + 1 } else { 1 };
        self.current.set((k, n));
        let cap = crate::params::ADAPTIVE_STEPS_PER_PERIOD;
        if n > cap {
            let cap = cap as f64;
            return Err(SimError::Budget {
                what: self.what,
                needed: format!(
                    "more than {cap:e} steps within the drive period from τ = {:.6e}",
                    k as f64 * self.period
                ),
                budget: format!("{cap:e} steps per drive period"),
                hint: "the tip–sample force grew too stiff to resolve where the motion went: \
                       soften the law (contact_stiffness, hamaker), check the gap (alpha5), \
                       or use a larger Ω",
            });
        }
        Ok(())
    }

    /// Forget the count of the current drive period (a new run).
    pub(crate) fn forget(&self) {
        self.current.set((i64::MIN, 0));
    }

    /// Steps taken since construction.
    pub(crate) fn work(&self) -> u64 {
        self.work.get()
    }
}

/// End points of the last step of a Runge–Kutta integrator, for Hermite dense output:
/// (τ0, z0, ż0) and (τ1, z1, ż1).
#[derive(Debug, Clone)]
pub(crate) struct HermiteStep {
    t0: f64,
    z0: DVector<f64>,
    f0: DVector<f64>,
    t1: f64,
    z1: DVector<f64>,
    f1: DVector<f64>,
}

impl HermiteStep {
    pub(crate) fn new(dim: usize) -> Self {
        let z = DVector::zeros(dim);
        HermiteStep {
            t0: 0.0,
            z0: z.clone(),
            f0: z.clone(),
            t1: 0.0,
            z1: z.clone(),
            f1: z,
        }
    }

    /// Record a step of `model` in region `r` from (t0, z0) to (t1, z1).
    pub(crate) fn record<S: TipSampleSystem + ?Sized>(
        &mut self,
        model: &S,
        r: Region,
        t0: f64,
        z0: &DVector<f64>,
        t1: f64,
        z1: &DVector<f64>,
    ) {
        self.t0 = t0;
        self.z0.copy_from(z0);
        model.rhs(r, t0, z0.as_slice(), self.f0.as_mut_slice());
        self.t1 = t1;
        self.z1.copy_from(z1);
        model.rhs(r, t1, z1.as_slice(), self.f1.as_mut_slice());
    }

    /// [W, W', W''] of the tip at τ.
    pub(crate) fn tip<S: TipSampleSystem + ?Sized>(&self, model: &S, tau: f64) -> [f64; 3] {
        let n = model.modes();
        let tip = model.tip();
        let w0 = [tip.dot(&self.z0.rows(0, n)), tip.dot(&self.f0.rows(0, n))];
        let w1 = [tip.dot(&self.z1.rows(0, n)), tip.dot(&self.f1.rows(0, n))];
        hermite_tip(self.t0, w0, self.t1, w1, tau)
    }

    /// Full state at τ.
    pub(crate) fn state(&self, tau: f64) -> DVector<f64> {
        DVector::from_iterator(
            self.z0.len(),
            (0..self.z0.len()).map(|i| {
                hermite_tip(
                    self.t0,
                    [self.z0[i], self.f0[i]],
                    self.t1,
                    [self.z1[i], self.f1[i]],
                    tau,
                )[0]
            }),
        )
    }
}

/// Cubic Hermite interpolation of the tip deflection inside a step from its end values
/// (W, W') — the dense output of the Runge–Kutta integrators. Returns [W, W', W''] at `tau`.
pub(crate) fn hermite_tip(t0: f64, w0: [f64; 2], t1: f64, w1: [f64; 2], tau: f64) -> [f64; 3] {
    let h = t1 - t0;
    if h <= 0.0 {
        return [w1[0], w1[1], 0.0];
    }
    let s = (tau - t0) / h;
    let (p0, m0, p1, m1) = (w0[0], w0[1] * h, w1[0], w1[1] * h);
    let h00 = 2.0 * s.powi(3) - 3.0 * s * s + 1.0;
    let h10 = s.powi(3) - 2.0 * s * s + s;
    let h01 = -2.0 * s.powi(3) + 3.0 * s * s;
    let h11 = s.powi(3) - s * s;
    let d00 = 6.0 * s * s - 6.0 * s;
    let d10 = 3.0 * s * s - 4.0 * s + 1.0;
    let d01 = -6.0 * s * s + 6.0 * s;
    let d11 = 3.0 * s * s - 2.0 * s;
    let e00 = 12.0 * s - 6.0;
    let e10 = 6.0 * s - 4.0;
    let e01 = -12.0 * s + 6.0;
    let e11 = 6.0 * s - 2.0;
    [
        h00 * p0 + h10 * m0 + h01 * p1 + h11 * m1,
        (d00 * p0 + d10 * m0 + d01 * p1 + d11 * m1) / h,
        (e00 * p0 + e10 * m0 + e01 * p1 + e11 * m1) / (h * h),
    ]
}
